// ROS 1 bag files read by celc itself (layout and checks: io/bag_file.hpp).
#include "io/bag_file.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cstring>
#include <memory>

namespace celc::detail {
namespace {

constexpr std::uint64_t kMaxRecordHeaderBytes = 1 << 20;
constexpr std::size_t kMagicBytes = 13;  // "#ROSBAG V2.0\n"

/// One record header read from the file: its fields and where its data is.
struct BagRecord {
  std::map<std::string, std::string> fields;
  std::uint64_t at = 0, data_at = 0, data_len = 0;
  std::uint8_t op() const {
    auto it = fields.find("op");
    return it != fields.end() && it->second.size() == 1 ? std::uint8_t(it->second[0]) : 0;
  }
  std::uint64_t end() const { return data_at + data_len; }
  /// The field `name` as a little-endian T; false when absent or of another size.
  template <typename T>
  bool value(const char* name, T& out) const {
    auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != sizeof(T)) return false;
    std::memcpy(&out, it->second.data(), sizeof(T));
    return true;
  }
  const std::string* text(const char* name) const {
    auto it = fields.find(name);
    return it == fields.end() ? nullptr : &it->second;
  }
};

/// Reads the record at `at`: its header (at most 1 MB) and data within the file.
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
/// "" when each lies inside it and has its '='.
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

/// The fields of a header held in [p, end) that badHeaderFields() accepted.
std::map<std::string, std::string> headerFields(const unsigned char* p, const unsigned char* end) {
  std::map<std::string, std::string> fields;
  while (p < end) {
    const auto flen = loadLE<std::uint32_t>(p);
    const std::string field(reinterpret_cast<const char*>(p + 4), flen);
    const std::size_t eq = field.find('=');
    fields.emplace(field.substr(0, eq), field.substr(eq + 1));
    p += 4 + flen;
  }
  return fields;
}

std::string fieldOr(const std::map<std::string, std::string>& fields, const char* name) {
  auto it = fields.find(name);
  return it == fields.end() ? std::string() : it->second;
}

/// Decompresses a bz2 or lz4 chunk into exactly plain.size() bytes; false when
/// the data is no such stream or gives another size.
bool decompress(const std::string& compression, const std::vector<unsigned char>& raw,
                std::vector<unsigned char>& plain) {
  if (compression == "bz2") {
    unsigned int out = unsigned(plain.size());
    return BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(plain.data()), &out,
                                      const_cast<char*>(reinterpret_cast<const char*>(raw.data())),
                                      unsigned(raw.size()), 0, 0) == BZ_OK &&
           out == plain.size();
  }
  // lz4: one LZ4 frame (magic 0x184D2204) holding the chunk
  LZ4F_dctx* raw_ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw_ctx, LZ4F_VERSION))) return false;
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> ctx(raw_ctx,
                                                                                  LZ4F_freeDecompressionContext);
  std::size_t in_at = 0, out_at = 0;
  while (true) {
    std::size_t in_n = raw.size() - in_at, out_n = plain.size() - out_at;
    const std::size_t hint = LZ4F_decompress(ctx.get(), plain.data() + out_at, &out_n, raw.data() + in_at, &in_n,
                                             nullptr);
    if (LZ4F_isError(hint)) return false;
    in_at += in_n;
    out_at += out_n;
    if (hint == 0) return in_at == raw.size() && out_at == plain.size();  // the frame ended
    if (in_n == 0 && out_n == 0) return false;  // input or output space exhausted mid-frame
  }
}

}  // namespace

BagFile::BagFile(const std::string& path, std::size_t max_packet_bytes)
    : f_(path), max_packet_bytes_(max_packet_bytes) {
  char magic[kMagicBytes];
  const std::size_t got = f_.read(magic, kMagicBytes);
  const std::string m(magic, got);
  if (m == "#ROSBAG V2.0\n") {
    version_ = 200;
    open20();
  } else if (m == "#ROSBAG V1.2\n") {
    version_ = 102;
    open12();
  } else {
    f_.fail(0, "unsupported bag version '" + printable(m.substr(0, 12), 12) + "' (2.0, 1.2)");
  }
}

bool BagFile::declared(std::uint32_t conn) const { return conn_ids_.count(conn) > 0; }

void BagFile::open20() {
  const BagRecord head = readRecord(f_, kMagicBytes, "bag header record");
  std::uint64_t index_pos = 0;
  std::uint32_t conn_count = 0, chunk_count = 0;
  if (head.op() != 0x03 || !head.value("index_pos", index_pos) || !head.value("conn_count", conn_count) ||
      !head.value("chunk_count", chunk_count))
    f_.fail(kMagicBytes, "not a bag header record (op 0x03 with index_pos, conn_count, chunk_count)");
  if (index_pos == 0)
    f_.fail(kMagicBytes, std::string("index position 0: the bag has no index (its recording was not closed)") +
                             kReindexHint);
  if (index_pos >= f_.size() || index_pos < head.end())
    f_.fail(kMagicBytes, "index position " + std::to_string(index_pos) + " beyond the end of the file (" +
                             std::to_string(f_.size()) + " bytes): truncated bag" + kReindexHint);
  const std::vector<std::uint64_t> chunks = readIndexSection(index_pos, head.data_at);
  if (connections_.size() != conn_count || chunks.size() != chunk_count)
    f_.fail(index_pos, "index section holds " + std::to_string(connections_.size()) + " connections and " +
                           std::to_string(chunks.size()) + " chunk infos, the header says " +
                           std::to_string(conn_count) + " and " + std::to_string(chunk_count) + kReindexHint);
  for (const std::uint64_t at : chunks) readChunk(at, index_pos);
}

/// The connection records (into connections_) and chunk infos (returned: the
/// chunk positions, each in [header_end, index_pos)) of the index section
/// [index_pos, end of file).
std::vector<std::uint64_t> BagFile::readIndexSection(std::uint64_t index_pos, std::uint64_t header_end) {
  std::vector<std::uint64_t> chunks;
  std::vector<unsigned char> data;
  for (std::uint64_t at = index_pos; at < f_.size();) {
    const BagRecord r = readRecord(f_, at, "index record");
    if (r.op() == 0x07) {
      BagConnection c;
      if (!r.value("conn", c.id)) f_.fail(at, "connection record without a connection id" + std::string(kReindexHint));
      const std::string* topic = r.text("topic");
      if (!topic) f_.fail(at, "connection record without a topic" + std::string(kReindexHint));
      c.topic = *topic;
      // its data is the connection header (topic, type, md5sum, definition)
      if (r.data_len > kMaxRecordHeaderBytes)
        f_.fail(at, "connection record data of " + std::to_string(r.data_len) + " bytes");
      data.resize(r.data_len);
      f_.seek(r.data_at);
      f_.readExact(data.data(), data.size(), "connection record data");
      if (const std::string e = badHeaderFields(data.data(), data.data() + data.size()); !e.empty())
        f_.fail(r.data_at, "connection record data: " + e + kReindexHint);
      const auto fields = headerFields(data.data(), data.data() + data.size());
      c.type = fieldOr(fields, "type");
      c.md5sum = fieldOr(fields, "md5sum");
      c.definition = fieldOr(fields, "message_definition");
      if (declared(c.id)) f_.fail(at, "a second connection record of connection " + std::to_string(c.id) + kReindexHint);
      conn_ids_.insert(c.id);
      connections_.push_back(std::move(c));
    } else if (r.op() == 0x06) {
      std::uint64_t chunk_pos = 0;
      if (!r.value("chunk_pos", chunk_pos) || chunk_pos < header_end || chunk_pos >= index_pos)
        f_.fail(at, "chunk info without a chunk position inside the file");
      // its data: `count` pairs (uint32 connection, uint32 messages)
      std::uint32_t count = 0;
      if (!r.value("count", count) || std::uint64_t(count) * 8 != r.data_len)
        f_.fail(at, "chunk info record of " + std::to_string(count) + " connection counts (8 bytes each) in " +
                        std::to_string(r.data_len) + " bytes of data" + kReindexHint);
      chunks.push_back(chunk_pos);
    } else {
      f_.fail(at, "unexpected record op " + std::to_string(int(r.op())) + " in the index section");
    }
    at = r.end();
  }
  return chunks;
}

/// The chunk record at `at` and the index data records after it; an
/// uncompressed chunk's records are walked (from the file) and checked here.
void BagFile::readChunk(std::uint64_t at, std::uint64_t index_pos) {
  const BagRecord r = readRecord(f_, at, "chunk record");
  Chunk c;
  c.at = at;
  c.data_at = r.data_at;
  c.data_len = r.data_len;
  const std::string* comp = r.text("compression");
  if (r.op() != 0x05 || !comp || !r.value("size", c.size))
    f_.fail(at, "not a chunk record (op 0x05 with compression and size)");
  c.compression = *comp;
  if (c.compression != "none" && c.compression != "bz2" && c.compression != "lz4")
    f_.fail(at, "unknown chunk compression '" + printable(c.compression, 16) + "' (none, bz2, lz4)");
  if (c.size > max_packet_bytes_)
    f_.fail(at, "chunk of " + std::to_string(c.size) + " bytes uncompressed, more than input.max_packet_bytes = " +
                    std::to_string(max_packet_bytes_));
  if (c.compression == "none" && c.size != c.data_len)
    f_.fail(at, "uncompressed chunk size " + std::to_string(c.size) + " differs from its data length " +
                    std::to_string(c.data_len));
  if (c.data_len > std::uint64_t(max_packet_bytes_) + (1 << 20))
    f_.fail(at, "chunk data of " + std::to_string(c.data_len) + " bytes, more than input.max_packet_bytes");
  ++compressions_[c.compression];
  chunks_.push_back(std::move(c));
  const Chunk& chunk = chunks_.back();
  std::vector<ChunkRecord> records;
  if (chunk.compression == "none") {
    std::vector<unsigned char> scratch;
    records = walkChunk(chunk, [&](std::size_t p, std::size_t n) {
      scratch.resize(std::max<std::size_t>(n, 1));
      f_.seek(chunk.data_at + p);
      f_.readExact(scratch.data(), n, "chunk data");
      return scratch.data();
    });
  }
  readIndexData(std::uint32_t(chunks_.size() - 1), r.end(), index_pos,
                chunk.compression == "none" ? &records : nullptr);
}

/// The index data records of chunk `chunk` from `from` on (they end at another
/// op or the index section); each entry is checked against `records` when given.
void BagFile::readIndexData(std::uint32_t chunk, std::uint64_t from, std::uint64_t index_pos,
                            const std::vector<ChunkRecord>* records) {
  std::vector<unsigned char> data;
  for (std::uint64_t r = from; r < index_pos;) {
    const BagRecord ix = readRecord(f_, r, "index data record");
    if (ix.op() != 0x04) break;
    IndexData d;
    d.data_at = ix.data_at;
    d.first = entries_.size();
    if (!ix.value("count", d.count) || std::uint64_t(d.count) * 12 != ix.data_len)
      f_.fail(r, "index data record whose count does not match its length");
    // The index decides which topic a message is read as: its connection must
    // be declared (and, checkEntries, be the one the message record names).
    if (!ix.value("conn", d.conn)) f_.fail(r, "index data record without a connection id" + std::string(kReindexHint));
    if (!declared(d.conn))
      f_.fail(r, "index data record of connection " + std::to_string(d.conn) +
                     ", which no connection record of the index declares" + kReindexHint);
    data.resize(ix.data_len);
    f_.seek(ix.data_at);
    f_.readExact(data.data(), data.size(), "index data");
    for (std::uint32_t k = 0; k < d.count; ++k) {
      const unsigned char* e = data.data() + 12 * std::size_t(k);
      BagEntry entry;
      entry.time_ns = std::uint64_t(loadLE<std::uint32_t>(e)) * 1000000000u + loadLE<std::uint32_t>(e + 4);
      entry.pos = loadLE<std::uint32_t>(e + 8);
      entry.chunk = chunk;
      entry.conn = d.conn;
      entries_.push_back(entry);
    }
    chunks_[chunk].index.push_back(d);
    if (records) checkEntries(chunks_[chunk], d, *records);
    r = ix.end();
  }
}

/// The records of chunk `c`'s uncompressed bytes, read through `bytes(at, n)`
/// (n bytes at offset at; at + n <= c.size is checked before): each header's
/// fields and each data length inside the chunk, only connection and message
/// data records, connection data well formed, each message record's
/// connection declared.
std::vector<ChunkRecord> BagFile::walkChunk(const Chunk& c, const Bytes& bytes) const {
  std::vector<ChunkRecord> records;
  auto bad = [&](std::size_t p, const std::string& what) {
    f_.fail(c.at, "chunk record at offset " + std::to_string(p) + ": " + what + kReindexHint);
  };
  const std::size_t size = c.size;
  std::size_t p = 0;
  while (p < size) {
    ChunkRecord rec;
    rec.at = std::uint32_t(p);
    if (size - p < 4) bad(rec.at, "cut header length");
    const auto hlen = loadLE<std::uint32_t>(bytes(p, 4));
    p += 4;
    if (hlen > size - p) bad(rec.at, "header of " + std::to_string(hlen) + " bytes beyond the chunk's end");
    const unsigned char* h = bytes(p, hlen);
    bool has_conn = false;
    for (std::size_t q = 0; q < hlen;) {
      if (hlen - q < 4) bad(rec.at, "cut header field");
      const auto flen = loadLE<std::uint32_t>(h + q);
      q += 4;
      if (flen > hlen - q) bad(rec.at, "header field longer than its header");
      const char* field = reinterpret_cast<const char*>(h + q);
      if (!std::memchr(field, '=', flen)) bad(rec.at, "header field without '='");
      if (flen == 4 && std::memcmp(field, "op=", 3) == 0) rec.op = std::uint8_t(field[3]);
      if (flen == 9 && std::memcmp(field, "conn=", 5) == 0) {
        rec.conn = loadLE<std::uint32_t>(h + q + 5);
        has_conn = true;
      }
      q += flen;
    }
    p += hlen;
    if (size - p < 4) bad(rec.at, "cut data length");
    rec.data_len = loadLE<std::uint32_t>(bytes(p, 4));
    p += 4;
    if (rec.data_len > size - p) bad(rec.at, "data of " + std::to_string(rec.data_len) + " bytes beyond the chunk's end");
    rec.data_at = std::uint32_t(p);
    p += rec.data_len;
    if (rec.op != 0x02 && rec.op != 0x07) bad(rec.at, "op " + std::to_string(int(rec.op)) + " inside a chunk");
    if (rec.op == 0x07) {
      const unsigned char* d = bytes(rec.data_at, rec.data_len);
      if (const std::string e = badHeaderFields(d, d + rec.data_len); !e.empty()) bad(rec.at, "connection data: " + e);
    }
    if (rec.op == 0x02 && !has_conn) bad(rec.at, "message data record without a connection id");
    if (rec.op == 0x02 && !declared(rec.conn))
      bad(rec.at, "message data record of connection " + std::to_string(rec.conn) +
                      ", which no connection record of the index declares");
    records.push_back(rec);
  }
  return records;
}

/// Every entry of `ix` on the start of a message data record of its connection.
void BagFile::checkEntries(const Chunk& c, const IndexData& ix, const std::vector<ChunkRecord>& records) const {
  for (std::uint32_t k = 0; k < ix.count; ++k) {
    const BagEntry& e = entries_[ix.first + k];
    const std::uint64_t byte = ix.data_at + 12 * std::uint64_t(k) + 8;
    auto it = std::lower_bound(records.begin(), records.end(), e.pos,
                               [](const ChunkRecord& r, std::uint64_t at) { return r.at < at; });
    if (it == records.end() || it->at != e.pos || it->op != 0x02)
      f_.fail(byte, "index entry offset " + std::to_string(e.pos) + " is not a message record of the chunk at byte " +
                        std::to_string(c.at) + kReindexHint);
    if (it->conn != ix.conn)
      f_.fail(byte, "index data record of connection " + std::to_string(ix.conn) +
                        " points at a message record of connection " + std::to_string(it->conn) + " (offset " +
                        std::to_string(e.pos) + " of the chunk at byte " + std::to_string(c.at) + ")" + kReindexHint);
  }
}

/// Reads chunk `chunk` into buf: decompressed, its records walked and every
/// index entry of it checked.
void BagFile::loadChunk(std::uint32_t chunk, ChunkBuffer& buf) {
  buf.chunk = -1;
  const Chunk& c = chunks_[chunk];
  std::vector<unsigned char>& target = c.compression == "none" ? buf.plain : buf.raw;
  target.resize(c.data_len);
  f_.seek(c.data_at);
  f_.readExact(target.data(), target.size(), "chunk data");
  if (c.compression != "none") {
    buf.plain.resize(c.size);
    if (!decompress(c.compression, buf.raw, buf.plain))
      f_.fail(c.at, "corrupt " + c.compression + " chunk (it does not decompress to its " + std::to_string(c.size) +
                        " bytes)");
  }
  buf.records = walkChunk(c, [&](std::size_t p, std::size_t) { return buf.plain.data() + p; });
  for (const IndexData& ix : c.index) checkEntries(c, ix, buf.records);
  buf.chunk = chunk;
}

std::vector<BagEntry> BagFile::messages(const std::vector<std::uint32_t>& conns) const {
  std::vector<BagEntry> out;
  for (const BagEntry& e : entries_)
    if (e.time_ns > 0 && std::find(conns.begin(), conns.end(), e.conn) != conns.end()) out.push_back(e);
  std::stable_sort(out.begin(), out.end(), [](const BagEntry& a, const BagEntry& b) { return a.time_ns < b.time_ns; });
  return out;
}

BagMessage BagFile::message(const BagEntry& e, ChunkBuffer& buf) {
  if (version_ == 102) return message12(e, buf);
  if (buf.chunk != std::int64_t(e.chunk)) loadChunk(e.chunk, buf);
  auto it = std::lower_bound(buf.records.begin(), buf.records.end(), e.pos,
                             [](const ChunkRecord& r, std::uint64_t at) { return r.at < at; });
  if (it == buf.records.end() || it->at != e.pos || it->op != 0x02)  // checkEntries() made sure of it
    f_.fail(chunks_[e.chunk].at, "no message record at offset " + std::to_string(e.pos) + kReindexHint);
  return {buf.plain.data() + it->data_at, it->data_len};
}

// ---- format 1.2 -------------------------------------------------------------------

void BagFile::open12() {
  // Every record's header and data within the file (a 1.4 GB header length
  // in a 178-byte file, found by the rosbag campaign).
  for (std::uint64_t at = kMagicBytes; at < f_.size();) {
    const BagRecord r = readRecord(f_, at, "record");
    records12_.push_back(at);
    at = r.end();
  }
  const BagRecord head = readRecord(f_, kMagicBytes, "bag header record");
  if (head.op() != 0x03 || !head.value("index_pos", index_pos12_))
    f_.fail(kMagicBytes, "not a bag header record (op 0x03 with index_pos)");
  if (index_pos12_ == 0)
    f_.fail(kMagicBytes, std::string("index position 0: the bag has no index (its recording was not closed)") +
                             kReindexHint);
  if (index_pos12_ > f_.size() || index_pos12_ < head.end() ||
      !std::binary_search(records12_.begin(), records12_.end(), index_pos12_))
    f_.fail(kMagicBytes, "index position " + std::to_string(index_pos12_) + " is no record's start before the end "
                             "of the file (" + std::to_string(f_.size()) + " bytes): truncated bag" + kReindexHint);
  std::vector<unsigned char> data;
  for (std::uint64_t at = index_pos12_; at < f_.size();) {
    const BagRecord r = readRecord(f_, at, "index data record");
    std::uint32_t ver = 1, count = 0;
    const std::string* topic = r.text("topic");
    if (r.op() != 0x04 || !r.value("ver", ver) || ver != 0 || !topic || !r.value("count", count) ||
        std::uint64_t(count) * 16 != r.data_len)
      f_.fail(at, "not a bag 1.2 index data record (op 0x04, ver 0, topic, count of 16-byte entries)" +
                      std::string(kReindexHint));
    auto c = std::find_if(connections_.begin(), connections_.end(), [&](const BagConnection& k) { return k.topic == *topic; });
    if (c == connections_.end()) {
      conn_ids_.insert(std::uint32_t(connections_.size()));
      connections_.push_back(BagConnection{std::uint32_t(connections_.size()), *topic, {}, {}, {}});
      c = connections_.end() - 1;
    }
    data.resize(r.data_len);
    f_.seek(r.data_at);
    f_.readExact(data.data(), data.size(), "index data");
    for (std::uint32_t k = 0; k < count; ++k) {
      const unsigned char* e = data.data() + 16 * std::size_t(k);
      BagEntry entry;
      entry.time_ns = std::uint64_t(loadLE<std::uint32_t>(e)) * 1000000000u + loadLE<std::uint32_t>(e + 4);
      entry.pos = loadLE<std::uint64_t>(e + 8);
      entry.conn = c->id;
      if (entry.pos < head.end() || entry.pos >= index_pos12_ ||
          !std::binary_search(records12_.begin(), records12_.end(), entry.pos))
        f_.fail(r.data_at + 16 * std::uint64_t(k) + 8, "index entry position " + std::to_string(entry.pos) +
                                                            " is not a record's start" + kReindexHint);
      entries_.push_back(entry);
    }
    at = r.end();
  }
  readDefinitions12();
}

/// Each 1.2 topic's type, MD5 sum and definition: the record at its first
/// entry (in time order) must be its message definition record.
void BagFile::readDefinitions12() {
  for (BagConnection& c : connections_) {
    const BagEntry* first = nullptr;  // the earliest, the first in file order among equal times
    for (const BagEntry& e : entries_)
      if (e.conn == c.id && (!first || e.time_ns < first->time_ns)) first = &e;
    if (!first) continue;
    const BagRecord d = readRecord(f_, first->pos, "message definition record");
    const std::string *topic = d.text("topic"), *md5 = d.text("md5"), *type = d.text("type"), *def = d.text("def");
    if (d.op() != 0x01 || !topic || *topic != c.topic || !md5 || !type || !def)
      f_.fail(d.at, "the first index entry of topic " + printable(c.topic, 100) +
                        " is not its message definition record (op 0x01 with topic, md5, type, def)" + kReindexHint);
    c.md5sum = *md5;
    c.type = *type;
    c.definition = *def;
  }
}

/// A 1.2 message: the record at e.pos, past at most kMaxDefinitions message
/// definition records, must be a message data record of the entry's topic.
BagMessage BagFile::message12(const BagEntry& e, ChunkBuffer& buf) {
  constexpr int kMaxDefinitions = 16;  // a writer puts one before a topic's first message
  BagRecord r = readRecord(f_, e.pos, "message record");
  for (int k = 0; k < kMaxDefinitions && r.op() == 0x01 && r.end() < index_pos12_; ++k)
    r = readRecord(f_, r.end(), "message record");
  const std::string* topic = r.text("topic");
  const std::string& want = connections_[e.conn].topic;
  if (r.op() != 0x02 || (topic && *topic != want))
    f_.fail(r.at, "index entry of topic " + printable(want, 100) + " points at no message data record of it" +
                      kReindexHint);
  if (r.data_len > max_packet_bytes_)
    f_.fail(r.at, "a message of " + std::to_string(r.data_len) + " bytes, more than input.max_packet_bytes");
  buf.plain.resize(r.data_len);
  f_.seek(r.data_at);
  f_.readExact(buf.plain.data(), buf.plain.size(), "message data");
  buf.chunk = -1;
  return {buf.plain.data(), buf.plain.size()};
}

}  // namespace celc::detail
