// ROS 1 bags through ROS's own bag library (Debian librosbag-storage-dev:
// format 2.0 with uncompressed, bz2 and lz4 chunks, and the older 1.2), with
// the few message layouts decoded directly (io/ros_messages.hpp).
//
// Before the library sees a format 2.0 file, its records are checked here so
// that a damaged or hostile file gives a one-line error instead of an
// unbounded allocation: the file header record (index position zero = an
// unindexed bag, position beyond the end = a truncated bag: both point at
// `rosbag reindex`), every record of the index section (connections and chunk
// infos) within the file, and every chunk's header (compression known,
// uncompressed size at most input.max_packet_bytes, data within the file), and
// every index data entry on a message record of the chunk whose connection id
// is the entry's and one the index declares (the index decides which topic,
// hence which layout, a message is decoded as).
//
// Layout of a 2.0 record: uint32 header_len, header (fields: uint32 len,
// "name=value"), uint32 data_len, data. op 0x03 bag header {index_pos,
// conn_count, chunk_count}, 0x05 chunk {compression, size}, 0x06 chunk info
// {ver, chunk_pos, start_time, end_time, count}, 0x07 connection {conn, topic},
// 0x04 index data, 0x02 message data.
#include <bzlib.h>
#include <console_bridge/console.h>
#include <roslz4/lz4s.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "io/aedat_readers.hpp"
#include "io/binary_file.hpp"
#include "io/ros_messages.hpp"

namespace celc::detail {
namespace {

constexpr std::uint64_t kMaxRecordHeaderBytes = 1 << 20;
const char* const kReindexHint = " (`rosbag reindex FILE` rebuilds the index of a bag cut short)";

/// One record header of a 2.0 bag: its fields and where its data is.
struct BagRecord {
  std::map<std::string, std::string> fields;
  std::uint64_t at = 0, data_at = 0, data_len = 0;
  std::uint8_t op() const {
    auto it = fields.find("op");
    return it != fields.end() && it->second.size() == 1 ? std::uint8_t(it->second[0]) : 0;
  }
  template <typename T>
  bool value(const char* name, T& out) const {
    auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != sizeof(T)) return false;
    std::memcpy(&out, it->second.data(), sizeof(T));
    return true;
  }
};

BagRecord readRecord(BinFile& f, std::uint64_t at, const char* what) {
  BagRecord r;
  r.at = at;
  f.seek(at);
  unsigned char len4[4];
  f.readExact(len4, 4, what);
  const auto hlen = loadLE<std::uint32_t>(len4);
  if (hlen > kMaxRecordHeaderBytes || hlen > f.size() - f.tell())
    f.fail(at, std::string(what) + ": record header length " + std::to_string(hlen) + " beyond the end of the file" +
                   kReindexHint);
  std::string h(hlen, '\0');
  f.readExact(&h[0], hlen, what);
  std::size_t p = 0;
  while (p < h.size()) {
    if (h.size() - p < 4) f.fail(at + 4 + p, std::string(what) + ": cut header field");
    const auto flen = loadLE<std::uint32_t>(reinterpret_cast<const unsigned char*>(h.data() + p));
    p += 4;
    if (flen > h.size() - p) f.fail(at + 4 + p, std::string(what) + ": header field longer than its header");
    const std::string field = h.substr(p, flen);
    p += flen;
    const std::size_t eq = field.find('=');
    if (eq == std::string::npos) f.fail(at + 4 + p - flen, std::string(what) + ": header field without '='");
    r.fields[field.substr(0, eq)] = field.substr(eq + 1);
  }
  f.readExact(len4, 4, what);
  r.data_len = loadLE<std::uint32_t>(len4);
  r.data_at = f.tell();
  if (r.data_len > f.size() - r.data_at)
    f.fail(at, std::string(what) + ": record data (" + std::to_string(r.data_len) +
                   " bytes) beyond the end of the file: truncated bag" + kReindexHint);
  return r;
}

/// Where the "len, name=value" fields of a header held in [p, end) go wrong:
/// "" when each lies inside it and has its '='. The bag library parses a
/// connection record's data this way and copies before it checks a length.
std::string badHeaderFields(const unsigned char* p, const unsigned char* end) {
  while (p < end) {
    if (end - p < 4) return "cut field length";
    const auto flen = loadLE<std::uint32_t>(p);
    p += 4;
    if (flen > std::uint64_t(end - p)) return "field of " + std::to_string(flen) + " bytes beyond its end";
    if (!std::memchr(p, '=', flen)) return "field without '='";
    p += flen;
  }
  return {};
}

/// One record inside a chunk: its op and, for a message data record, its connection id.
struct ChunkRecord {
  std::uint8_t op = 0;
  std::uint32_t conn = 0;
  bool has_conn = false;
};

/// The records of one decompressed chunk (offset -> record): each header's
/// fields and each data length must lie inside the chunk, and a message data
/// record must name a connection of `conns` (the index section's).
std::map<std::uint32_t, ChunkRecord> chunkRecords(const BinFile& f, std::uint64_t chunk_at,
                                                  const std::vector<unsigned char>& b,
                                                  const std::set<std::uint32_t>& conns) {
  std::map<std::uint32_t, ChunkRecord> ops;
  auto bad = [&](std::size_t p, const std::string& what) {
    f.fail(chunk_at, "chunk record at offset " + std::to_string(p) + ": " + what + kReindexHint);
  };
  std::size_t p = 0;
  while (p < b.size()) {
    const std::size_t start = p;
    if (b.size() - p < 4) bad(start, "cut header length");
    const auto hlen = loadLE<std::uint32_t>(b.data() + p);
    p += 4;
    if (hlen > b.size() - p) bad(start, "header of " + std::to_string(hlen) + " bytes beyond the chunk's end");
    const std::size_t hend = p + hlen;
    std::uint8_t op = 0;
    ChunkRecord rec;
    while (p < hend) {
      if (hend - p < 4) bad(start, "cut header field");
      const auto flen = loadLE<std::uint32_t>(b.data() + p);
      p += 4;
      if (flen > hend - p) bad(start, "header field longer than its header");
      const char* field = reinterpret_cast<const char*>(b.data() + p);
      const void* eq = std::memchr(field, '=', flen);
      if (!eq) bad(start, "header field without '='");
      if (flen == 4 && std::memcmp(field, "op=", 3) == 0) op = std::uint8_t(field[3]);
      if (flen == 9 && std::memcmp(field, "conn=", 5) == 0) {
        rec.conn = loadLE<std::uint32_t>(b.data() + p + 5);
        rec.has_conn = true;
      }
      p += flen;
    }
    if (b.size() - p < 4) bad(start, "cut data length");
    const auto dlen = loadLE<std::uint32_t>(b.data() + p);
    p += 4;
    if (dlen > b.size() - p) bad(start, "data of " + std::to_string(dlen) + " bytes beyond the chunk's end");
    p += dlen;
    if (op != 0x02 && op != 0x07) bad(start, "op " + std::to_string(int(op)) + " inside a chunk");
    if (op == 0x07)
      if (const std::string e = badHeaderFields(b.data() + p - dlen, b.data() + p); !e.empty())
        bad(start, "connection data: " + e);
    if (op == 0x02 && !rec.has_conn) bad(start, "message data record without a connection id");
    if (op == 0x02 && !conns.count(rec.conn))
      bad(start, "message data record of connection " + std::to_string(rec.conn) +
                     ", which no connection record of the index declares");
    rec.op = op;
    ops[std::uint32_t(start)] = rec;
  }
  return ops;
}

/// The checks of a format 2.0 bag described at the top of the file.
/// Returns the number of chunks per compression.
std::map<std::string, int> checkBag20(const std::string& path, const ReaderOptions& o) {
  std::map<std::string, int> compressions;
  BinFile f(path);
  const std::size_t magic = 13;  // "#ROSBAG V2.0\n"
  const BagRecord head = readRecord(f, magic, "bag header record");
  std::uint64_t index_pos = 0;
  std::uint32_t conn_count = 0, chunk_count = 0;
  if (head.op() != 0x03 || !head.value("index_pos", index_pos) || !head.value("conn_count", conn_count) ||
      !head.value("chunk_count", chunk_count))
    f.fail(magic, "not a bag header record (op 0x03 with index_pos, conn_count, chunk_count)");
  if (index_pos == 0)
    f.fail(magic, std::string("index position 0: the bag has no index (its recording was not closed)") +
                      kReindexHint);
  if (index_pos >= f.size() || index_pos < head.data_at + head.data_len)
    f.fail(magic, "index position " + std::to_string(index_pos) + " beyond the end of the file (" +
                      std::to_string(f.size()) + " bytes): truncated bag" + kReindexHint);
  std::vector<std::uint64_t> chunks;
  std::uint32_t conns = 0;
  std::set<std::uint32_t> conn_ids;
  for (std::uint64_t at = index_pos; at < f.size();) {
    const BagRecord r = readRecord(f, at, "index record");
    if (r.op() == 0x07) {
      ++conns;
      std::uint32_t id = 0;
      if (!r.value("conn", id)) f.fail(at, "connection record without a connection id" + std::string(kReindexHint));
      conn_ids.insert(id);
      // its data is the connection header (topic, type, md5sum, definition): found by the rosbag fuzz target
      if (r.data_len > kMaxRecordHeaderBytes)
        f.fail(at, "connection record data of " + std::to_string(r.data_len) + " bytes");
      std::vector<unsigned char> data(r.data_len);
      f.seek(r.data_at);
      f.readExact(data.data(), data.size(), "connection record data");
      if (const std::string e = badHeaderFields(data.data(), data.data() + data.size()); !e.empty())
        f.fail(r.data_at, "connection record data: " + e + kReindexHint);
    } else if (r.op() == 0x06) {
      std::uint64_t chunk_pos = 0;
      if (!r.value("chunk_pos", chunk_pos) || chunk_pos < head.data_at || chunk_pos >= index_pos)
        f.fail(at, "chunk info without a chunk position inside the file");
      // Its data: `count` pairs (uint32 connection, uint32 messages), which the
      // library reads one by one from the file without a bound.
      std::uint32_t count = 0;
      if (!r.value("count", count) || std::uint64_t(count) * 8 != r.data_len)
        f.fail(at, "chunk info record of " + std::to_string(count) + " connection counts (8 bytes each) in " +
                       std::to_string(r.data_len) + " bytes of data" + kReindexHint);
      chunks.push_back(chunk_pos);
    } else
      f.fail(at, "unexpected record op " + std::to_string(int(r.op())) + " in the index section");
    at = r.data_at + r.data_len;
  }
  if (conns != conn_count || chunks.size() != chunk_count)
    f.fail(index_pos, "index section holds " + std::to_string(conns) + " connections and " +
                          std::to_string(chunks.size()) + " chunk infos, the header says " +
                          std::to_string(conn_count) + " and " + std::to_string(chunk_count) + kReindexHint);
  std::vector<unsigned char> raw, plain;  // reused: one allocation for every chunk
  for (const std::uint64_t at : chunks) {
    const BagRecord c = readRecord(f, at, "chunk record");
    std::uint32_t size = 0;
    auto comp = c.fields.find("compression");
    if (c.op() != 0x05 || comp == c.fields.end() || !c.value("size", size))
      f.fail(at, "not a chunk record (op 0x05 with compression and size)");
    if (comp->second != "none" && comp->second != "bz2" && comp->second != "lz4")
      f.fail(at, "unknown chunk compression '" + printable(comp->second, 16) + "' (none, bz2, lz4)");
    if (size > o.max_packet_bytes)
      f.fail(at, "chunk of " + std::to_string(size) + " bytes uncompressed, more than input.max_packet_bytes = " +
                     std::to_string(o.max_packet_bytes));
    if (comp->second == "none" && size != c.data_len)
      f.fail(at, "uncompressed chunk size " + std::to_string(size) + " differs from its data length " +
                     std::to_string(c.data_len));
    ++compressions[comp->second];
    const std::uint64_t end = c.data_at + c.data_len;
    // The library reads the chunk's records from its (decompressed) buffer
    // without bounds of its own: every record must parse inside the chunk, and
    // every index entry must point at the start of a message data record.
    if (c.data_len > std::uint64_t(o.max_packet_bytes) + (1 << 20))
      f.fail(at, "chunk data of " + std::to_string(c.data_len) + " bytes, more than input.max_packet_bytes");
    raw.resize(c.data_len);
    f.seek(c.data_at);
    f.readExact(raw.data(), raw.size(), "chunk data");
    if (comp->second == "none") {
      plain.assign(raw.begin(), raw.end());
    } else {
      plain.resize(size);
      unsigned int out = size;
      const bool ok =
          comp->second == "bz2"
              ? BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(plain.data()), &out,
                                           reinterpret_cast<char*>(raw.data()), unsigned(raw.size()), 0, 0) == BZ_OK
              : roslz4_buffToBuffDecompress(reinterpret_cast<char*>(raw.data()), unsigned(raw.size()),
                                            reinterpret_cast<char*>(plain.data()), &out) == ROSLZ4_OK;
      if (!ok || out != size)
        f.fail(at, "corrupt " + comp->second + " chunk (it does not decompress to its " + std::to_string(size) +
                       " bytes)");
    }
    const std::map<std::uint32_t, ChunkRecord> records = chunkRecords(f, at, plain, conn_ids);
    // The index records after the chunk: each entry on a message record of the chunk.
    for (std::uint64_t r = end; r < index_pos;) {
      const BagRecord ix = readRecord(f, r, "index data record");
      if (ix.op() != 0x04) break;
      std::uint32_t count = 0, conn = 0;
      if (!ix.value("count", count) || std::uint64_t(count) * 12 != ix.data_len)
        f.fail(r, "index data record whose count does not match its length");
      // The index decides which topic a message is read as: its connection
      // must be declared and be the one the message record itself names.
      if (!ix.value("conn", conn)) f.fail(r, "index data record without a connection id" + std::string(kReindexHint));
      if (!conn_ids.count(conn))
        f.fail(r, "index data record of connection " + std::to_string(conn) +
                      ", which no connection record of the index declares" + kReindexHint);
      std::vector<unsigned char> entries(ix.data_len);
      f.seek(ix.data_at);
      f.readExact(entries.data(), entries.size(), "index data");
      for (std::uint32_t k = 0; k < count; ++k) {
        const auto offset = loadLE<std::uint32_t>(entries.data() + 12 * k + 8);
        auto it = records.find(offset);
        if (it == records.end() || it->second.op != 0x02)
          f.fail(ix.data_at + 12 * k + 8, "index entry offset " + std::to_string(offset) +
                                               " is not a message record of the chunk at byte " + std::to_string(at) +
                                               kReindexHint);
        if (it->second.conn != conn)
          f.fail(ix.data_at + 12 * k + 8, "index data record of connection " + std::to_string(conn) +
                                               " points at a message record of connection " +
                                               std::to_string(it->second.conn) + " (offset " + std::to_string(offset) +
                                               " of the chunk at byte " + std::to_string(at) + ")" + kReindexHint);
      }
      r = ix.data_at + ix.data_len;
    }
  }
  return compressions;
}

/// A topic of the bag: type, count, record-time span.
struct TopicInfo {
  std::string topic, type;
  std::uint64_t messages = 0;
  double t_first = 0.0, t_last = 0.0;
};

class RosBagReader final : public EventReader {
 public:
  RosBagReader(const std::string& path, const ReaderOptions& o) {
    path_ = path;
    options_ = o;
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // errors come back as exceptions
    {
      BinFile f(path);
      char magic[13];
      const std::size_t got = f.read(magic, 13);
      const std::string m(magic, got);
      if (m == "#ROSBAG V2.0\n") {
        std::string chunks;
        for (const auto& [name, n] : checkBag20(path, o))
          chunks += (chunks.empty() ? "" : ", ") + std::to_string(n) + " " + name;
        notes_.push_back("bag format 2.0, chunks: " + (chunks.empty() ? std::string("none") : chunks));
      } else if (m == "#ROSBAG V1.2\n") {
        // The same record framing without chunks: every record's header and
        // data within the file before the library sizes a buffer from them
        // (a 1.4 GB header length in a 178-byte file, found by the rosbag campaign).
        for (std::uint64_t at = 13; at < f.size();) {
          const BagRecord r = readRecord(f, at, "record");
          at = r.data_at + r.data_len;
        }
        notes_.push_back("bag format 1.2 (no chunks)");
      } else {
        f.fail(0, "unsupported bag version '" + printable(m.substr(0, 12), 12) + "' (2.0, 1.2)");
      }
    }
    try {
      bag_.open(path, rosbag::bagmode::Read);
    } catch (const rosbag::BagUnindexedException&) {
      throw IoError(path + ": the bag has no index" + kReindexHint);
    } catch (const std::exception& e) {
      throw IoError(path + ": " + printable(e.what(), 200) + kReindexHint);
    }
    catalogue();
    events_topic_ = pickTopic(o.topic_events, {ros_type::kEventArray}, "events", "topic_events", true);
    imu_topic_ = pickTopic(o.topic_imu, {ros_type::kImu}, "IMU", "topic_imu", false);
    pose_topic_ = pickTopic(o.topic_pose, {ros_type::kPoseStamped, ros_type::kOdometry}, "pose", "topic_pose", false);
    for (const TopicInfo& t : topics_) {
      char line[512];
      const double span = t.t_last - t.t_first;
      std::snprintf(line, sizeof line, "topic %s: %s, %llu messages, %.4g Hz%s", printable(t.topic, 100).c_str(),
                    printable(t.type, 80).c_str(), static_cast<unsigned long long>(t.messages),
                    t.messages > 1 && span > 0 ? double(t.messages - 1) / span : 0.0,
                    t.topic == events_topic_ ? " (events)" : t.topic == imu_topic_ ? " (IMU)"
                    : t.topic == pose_topic_ ? " (ground truth)" : "");
      notes_.push_back(line);
    }
    readCameraInfo();
    events_view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(events_topic_));
    it_ = events_view_->begin();
    // The sensor size: the first EventArray's (CameraInfo's when it says 0), unless the options give one.
    if (it_ != events_view_->end()) {
      loadMessage(*it_, "events", msg_);
      const EventArrayView v = decodeEvents();
      if (v.width > 0 && v.height > 0) {
        width_ = int(std::min<std::uint32_t>(v.width, 1u << 30));
        height_ = int(std::min<std::uint32_t>(v.height, 1u << 30));
      }
      first_loaded_ = true;
    }
    if (width_ > kMaxReaderSensorSide || height_ > kMaxReaderSensorSide)
      throw IoError(path_ + ": topic " + events_topic_ + ": a " + std::to_string(width_) + "x" +
                    std::to_string(height_) + " sensor (at most " + std::to_string(kMaxReaderSensorSide) + ")");
    if (o.width > 0) width_ = o.width;
    if (o.height > 0) height_ = o.height;
  }
  Format format() const override { return Format::RosBag; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    while (batch.size() < max) {
      if (cur_ == count_) {
        if (!nextMessage()) break;
        continue;
      }
      drain(batch, max);
    }
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    std::vector<ImuSample> imu;
    if (imu_topic_.empty()) return imu;
    forEach(imu_topic_, "IMU", [&](const unsigned char* p, std::size_t n) { imu.push_back(decodeImu(p, n)); });
    return imu;
  }

  std::vector<PoseSample> readPoses() override {
    std::vector<PoseSample> poses;
    if (pose_topic_.empty()) return poses;
    const bool odometry = typeOf(pose_topic_) == ros_type::kOdometry;
    forEach(pose_topic_, "pose", [&](const unsigned char* p, std::size_t n) {
      poses.push_back(odometry ? decodeOdometry(p, n) : decodePoseStamped(p, n));
    });
    return poses;
  }

  /// The camera of the first sensor_msgs/CameraInfo message (false when the bag has none).
  bool cameraInfo(RosCameraInfo& out) const {
    if (!has_info_) return false;
    out = info_;
    return true;
  }

 private:
  void catalogue() {
    rosbag::View all(bag_);
    std::map<std::string, TopicInfo> by_topic;
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      TopicInfo& t = by_topic[c->topic];
      t.topic = c->topic;
      if (!t.type.empty() && t.type != c->datatype)
        throw IoError(path_ + ": topic " + printable(c->topic, 100) + " carries two message types, " +
                      printable(t.type, 80) + " and " + printable(c->datatype, 80));
      t.type = c->datatype;
    }
    for (auto& [name, t] : by_topic) {
      rosbag::View v(bag_, rosbag::TopicQuery(name));
      t.messages = v.size();
      if (t.messages > 0) {
        t.t_first = v.getBeginTime().toSec();
        t.t_last = v.getEndTime().toSec();
      }
      topics_.push_back(t);
    }
  }

  std::string typeOf(const std::string& topic) const {
    for (const TopicInfo& t : topics_)
      if (t.topic == topic) return t.type;
    return {};
  }

  std::string topicList() const {
    std::string s;
    for (const TopicInfo& t : topics_) s += (s.empty() ? "" : ", ") + printable(t.topic, 100) + " (" + printable(t.type, 80) + ")";
    return s.empty() ? std::string("none") : s;
  }

  /// The topic named in the options (its type checked), else the one topic of
  /// one of `types`; none is an error only when `required`.
  std::string pickTopic(const std::string& given, const std::vector<std::string>& types, const char* what,
                        const char* key, bool required) {
    auto allowed = [&](const std::string& type) { return std::find(types.begin(), types.end(), type) != types.end(); };
    std::string expected;
    for (const auto& t : types) expected += (expected.empty() ? "" : " or ") + t;
    if (!given.empty()) {
      const std::string type = typeOf(given);
      if (type.empty())
        throw IoError(path_ + ": no topic " + printable(given, 100) + " (input." + key + "); topics: " + topicList());
      if (!allowed(type))
        throw IoError(path_ + ": topic " + printable(given, 100) + ": unknown message type " + printable(type, 80) +
                      " for the " + what + " topic (expected " + expected + ")");
      return given;
    }
    std::vector<std::string> found;
    for (const TopicInfo& t : topics_)
      if (allowed(t.type)) found.push_back(t.topic);
    if (found.size() > 1) {
      std::string names;
      for (const auto& n : found) names += (names.empty() ? "" : ", ") + printable(n, 100);
      throw IoError(path_ + ": several " + what + " topics (" + names + "): choose one with input." + key +
                    " (--" + std::string(key).replace(5, 1, "-") + ")");
    }
    if (found.empty() && required)
      throw IoError(path_ + ": no " + expected + " topic for the " + what + "; topics: " + topicList() +
                    " (input." + key + " names the topic)");
    return found.empty() ? std::string() : found.front();
  }

  void readCameraInfo() {
    for (const TopicInfo& t : topics_) {
      if (t.type != ros_type::kCameraInfo) continue;
      rosbag::View v(bag_, rosbag::TopicQuery(t.topic));
      for (const rosbag::MessageInstance& m : v) {
        loadMessage(m, "camera info", side_);
        try {
          info_ = decodeCameraInfo(side_.data(), side_.size());
        } catch (const RosDecodeError& e) {
          throw IoError(path_ + ": topic " + printable(t.topic, 100) + ", message 0, byte " +
                        std::to_string(e.offset) + " of the message: " + e.what());
        }
        has_info_ = true;
        char line[200];
        std::snprintf(line, sizeof line, "camera info on %s: %ux%u, fx %.6g fy %.6g cx %.6g cy %.6g, %s",
                      printable(t.topic, 60).c_str(), info_.width, info_.height, info_.K[0], info_.K[4],
                      info_.K[2], info_.K[5], printable(info_.distortion_model, 30).c_str());
        notes_.push_back(line);
        if (info_.width > 0 && info_.height > 0 && info_.width <= std::uint32_t(kMaxReaderSensorSide) &&
            info_.height <= std::uint32_t(kMaxReaderSensorSide)) {
          width_ = int(info_.width);
          height_ = int(info_.height);
        }
        return;
      }
    }
  }

  /// Copies the serialised message `m` into `buf` (msg_ for events; side_ for
  /// the other topics, so that readImu() between next() calls keeps the events message).
  void loadMessage(const rosbag::MessageInstance& m, const char* what, std::vector<unsigned char>& buf) {
    try {
      const std::uint32_t n = m.size();
      if (n > options_.max_packet_bytes)
        throw IoError(path_ + ": topic " + printable(m.getTopic(), 100) + ": a " + what + " message of " +
                      std::to_string(n) + " bytes, more than input.max_packet_bytes");
      buf.resize(n);
      ros::serialization::OStream s(buf.data(), n);
      m.write(s);
    } catch (const IoError&) {
      throw;
    } catch (const std::exception& e) {
      throw IoError(path_ + ": topic " + printable(m.getTopic(), 100) +
                    (&buf == &msg_ ? ", message " + std::to_string(msg_index_) : std::string()) + ": " +
                    printable(e.what(), 200) + kReindexHint);
    }
  }

  EventArrayView decodeEvents() {
    try {
      return decodeEventArray(msg_.data(), msg_.size());
    } catch (const RosDecodeError& e) {
      throw IoError(path_ + ": topic " + printable(events_topic_, 100) + ", message " + std::to_string(msg_index_) +
                    ", byte " + std::to_string(e.offset) + " of the message: " + e.what());
    }
  }

  bool nextMessage() {
    if (first_loaded_) {
      first_loaded_ = false;
    } else {
      if (it_ == events_view_->end()) return false;
      ++it_;
      ++msg_index_;
      if (it_ == events_view_->end()) return false;
      loadMessage(*it_, "events", msg_);
    }
    if (it_ == events_view_->end()) return false;
    const EventArrayView v = decodeEvents();
    events_ = v.events;
    events_offset_ = v.events_offset;
    count_ = v.count;
    cur_ = 0;
    return true;
  }

  void drain(std::vector<Event>& batch, std::size_t max) {
    for (; cur_ < count_ && batch.size() < max; ++cur_) {
      const RosEvent r = loadRosEvent(events_ + kRosEventBytes * cur_);
      auto where = [&] {
        return path_ + ": topic " + printable(events_topic_, 100) + ", message " + std::to_string(msg_index_) +
               ", event " + std::to_string(cur_);
      };
      if ((width_ > 0 && r.x >= width_) || (height_ > 0 && r.y >= height_)) {
        outsideSensor(where(), double(r.x), double(r.y));
        continue;
      }
      Event e;
      try {
        e.t = rosTimeSeconds(r.sec, r.nsec, events_offset_ + kRosEventBytes * cur_ + 4);
      } catch (const RosDecodeError& err) {
        throw IoError(where() + ": " + err.what());
      }
      e.x = float(r.x);
      e.y = float(r.y);
      e.on = r.on;
      admit(batch, e, where);
    }
  }

  template <class Decode>
  void forEach(const std::string& topic, const char* what, Decode&& decode) {
    rosbag::View v(bag_, rosbag::TopicQuery(topic));
    std::uint64_t index = 0;
    for (const rosbag::MessageInstance& m : v) {
      loadMessage(m, what, side_);
      try {
        decode(side_.data(), side_.size());
      } catch (const RosDecodeError& e) {
        throw IoError(path_ + ": topic " + printable(topic, 100) + ", message " + std::to_string(index) + ", byte " +
                      std::to_string(e.offset) + " of the message: " + e.what());
      }
      ++index;
    }
  }

  rosbag::Bag bag_;
  std::vector<TopicInfo> topics_;
  std::string events_topic_, imu_topic_, pose_topic_;
  RosCameraInfo info_;
  bool has_info_ = false;
  std::unique_ptr<rosbag::View> events_view_;
  rosbag::View::iterator it_;
  bool first_loaded_ = false;
  std::uint64_t msg_index_ = 0;
  std::vector<unsigned char> msg_;   ///< the current events message
  std::vector<unsigned char> side_;  ///< a message of another topic
  const unsigned char* events_ = nullptr;
  std::size_t events_offset_ = 0;
  std::uint32_t count_ = 0, cur_ = 0;
};

}  // namespace

std::unique_ptr<EventReader> openRosBag(const std::string& path, const ReaderOptions& o) {
  return std::make_unique<RosBagReader>(path, o);
}

bool bagCameraModel(const std::string& path, CameraModel& camera) {
  RosCameraInfo info;
  if (!RosBagReader(path, ReaderOptions{}).cameraInfo(info)) return false;
  auto fail = [&](const std::string& what) { throw IoError(path + ": sensor_msgs/CameraInfo: " + what); };
  if (info.width == 0 || info.height == 0 || info.width > std::uint32_t(kMaxReaderSensorSide) ||
      info.height > std::uint32_t(kMaxReaderSensorSide))
    fail("image size " + std::to_string(info.width) + "x" + std::to_string(info.height) + " out of range");
  camera = CameraModel{};
  camera.width = int(info.width);
  camera.height = int(info.height);
  camera.fx = info.K[0];
  camera.fy = info.K[4];
  camera.cx = info.K[2];
  camera.cy = info.K[5];
  const std::string& model = info.distortion_model;
  bool any = false;
  for (double d : info.D) any |= d != 0.0;
  if (!any) {
    camera.distortion = DistortionModel::None;
  } else if (model == "plumb_bob" || model == "radtan" || (model == "rational_polynomial" && info.D.size() >= 5)) {
    if (model == "rational_polynomial")
      for (std::size_t i = 5; i < info.D.size(); ++i)
        if (info.D[i] != 0.0) fail("rational_polynomial with k4..k6 is not supported (radtan k1 k2 p1 p2 k3 only)");
    camera.distortion = DistortionModel::RadTan;
    for (std::size_t i = 0; i < 5 && i < info.D.size(); ++i) camera.coeffs[i] = info.D[i];
  } else if (model == "equidistant" || model == "fisheye") {
    camera.distortion = DistortionModel::Equidistant;
    for (std::size_t i = 0; i < 4 && i < info.D.size(); ++i) camera.coeffs[i] = info.D[i];
  } else {
    fail("distortion model '" + printable(model, 30) + "' is not supported (plumb_bob, equidistant)");
  }
  if (const std::string err = camera.validate(); !err.empty()) fail(err);
  return true;
}

}  // namespace celc::detail
