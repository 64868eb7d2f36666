// AEDAT 4.0 (DV): "#!AER-DAT4.0\r\n", an int32 size then the IOHeader flatbuffer
// ("IOHE": compression {0 none, 1 LZ4, 2 LZ4 high, 3 Zstd, 4 Zstd high}, the
// data table's byte (-1 when absent), the XML stream description), then
// packets: int32 stream id, int32 size, size bytes of one compressed frame
// holding a flatbuffer payload ("EVTS" events, "IMUS" IMU samples [g, deg/s]),
// and the file data table ("FTAB", compressed like packets) at its byte: per
// packet its payload's byte (its 8-byte header precedes it), stream, size,
// element count and time range. The tables, their field ids and types are in
// aedat4.fbs; flatc generates the accessors, and every buffer passes
// flatbuffers::Verifier before one field of it is read.
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>

#include <flatbuffers/flatbuffers.h>

#include "io/aedat4_generated.h"
#include "io/aedat_readers.hpp"
#include "io/binary_file.hpp"

namespace celc::detail {
namespace {

/// Largest Zstd window a packet may ask for: 2^25 = 32 MB (zstd's default limit
/// is 2^27; a window is allocated whole before any byte is decoded).
constexpr int kZstdWindowLogMax = 25;

struct StreamInfo {
  int id = -1;
  std::string type;
  int width = 0, height = 0;
};

std::string xmlAttr(const std::string& block, const std::string& key) {
  const std::string k = "key=\"" + key + "\"";
  std::size_t p = block.find(k);
  if (p == std::string::npos) return {};
  p = block.find('>', p);
  if (p == std::string::npos) return {};
  std::size_t e = block.find('<', p);
  if (e == std::string::npos) return {};
  return block.substr(p + 1, e - p - 1);
}

std::vector<StreamInfo> parseStreams(const std::string& xml) {
  std::vector<StreamInfo> out;
  std::vector<std::pair<std::size_t, int>> starts;
  const std::string marker = "/outInfo/";
  std::size_t p = 0;
  while ((p = xml.find(marker, p)) != std::string::npos) {
    p += marker.size();
    std::size_t e = p;
    while (e < xml.size() && std::isdigit(static_cast<unsigned char>(xml[e]))) ++e;
    if (e > p && e < xml.size() && xml[e] == '/' && e + 1 < xml.size() && xml[e + 1] == '"' && e - p < 6)
      starts.emplace_back(p, std::stoi(xml.substr(p, e - p)));
  }
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const std::size_t end = i + 1 < starts.size() ? starts[i + 1].first : xml.size();
    const std::string block = xml.substr(starts[i].first, end - starts[i].first);
    StreamInfo s;
    s.id = starts[i].second;
    s.type = xmlAttr(block, "typeIdentifier");
    // A size of any number of digits is read (beyond 9 digits as INT_MAX), so
    // that the bound check refuses it like any other size above the limit.
    auto side = [](const std::string& v) {
      if (v.empty() || !std::all_of(v.begin(), v.end(), ::isdigit)) return 0;
      const std::size_t lead = std::min(v.find_first_not_of('0'), v.size());
      return v.size() - lead > 9 ? std::numeric_limits<int>::max() : std::stoi(v);
    };
    s.width = side(xmlAttr(block, "sizeX"));
    s.height = side(xmlAttr(block, "sizeY"));
    out.push_back(s);
  }
  return out;
}

namespace fbs = celc::aedat4;

/// Nesting of the tables in aedat4.fbs: a root table and the tables of its
/// vector (IMU samples, data table entries); the verifier refuses deeper.
constexpr flatbuffers::uoffset_t kFbMaxDepth = 4;

/// A flatbuffer that cannot be read: `offset` is the byte within its buffer
/// the message is about (0 for the buffer as a whole).
struct FbError : std::runtime_error {
  FbError(std::size_t at, const std::string& what) : std::runtime_error(what), offset(at) {}
  std::size_t offset;
};

/// Which flatbuffer of the file: the IOHeader, or a packet payload / the data
/// table (decompressed).
enum class FbKind {
  /// Size-prefixed. Its scalars may lie off their alignment (DV-derived files
  /// hold the int64 data table position at 4 mod 8): they are read with
  /// flatbuffers::ReadScalar, which the library makes safe for that; its
  /// string must be 4-aligned.
  Header,
  /// Size-prefixed or not; every scalar, vector and struct field aligned (the
  /// structs of a vector are copied before they are read).
  Packet,
};

/// The root table T of the flatbuffer in `data[0, size)` (`data` allocated
/// by new, so offsets and addresses share their alignment), after
/// flatbuffers::Verifier has checked every offset, vtable, vector and string
/// of it against the buffer, and their alignment for a packet, with at most
/// kFbMaxDepth nested tables and one table per 8 bytes. The buffer is
/// size-prefixed (its identifier at byte 8, its size prefix at most the bytes
/// there) or, for a packet, not (identifier at byte 4); the identifier must
/// be `ident`. Throws FbError naming what failed.
template <typename T>
const T* verifiedRoot(const unsigned char* data, std::size_t size, const char* ident, FbKind kind) {
  const bool prefix_required = kind == FbKind::Header;
  const std::string id(ident);
  if (size < 12)
    throw FbError(0, "a flatbuffer of " + std::to_string(size) + " bytes, shorter than its 12-byte header");
  if (size >= FLATBUFFERS_MAX_BUFFER_SIZE)
    throw FbError(0, "a flatbuffer of " + std::to_string(size) + " bytes, beyond the format's 2 GB");
  const bool prefixed = prefix_required || !flatbuffers::BufferHasIdentifier(data, ident, false);
  if (!flatbuffers::BufferHasIdentifier(data, ident, prefixed))
    throw FbError(prefixed ? 8 : 4, (prefix_required ? "flatbuffer" : "payload") +
                                        std::string(" identifier is not '") + id + "'");
  std::size_t len = size;
  if (prefixed) {
    const auto declared = flatbuffers::ReadScalar<flatbuffers::uoffset_t>(data);
    if (std::uint64_t(declared) + 4 > size)
      throw FbError(0, "flatbuffer size prefix " + std::to_string(declared) + " exceeds the buffer of " +
                           std::to_string(size) + " bytes");
    len = std::size_t(declared) + 4;
  }
  flatbuffers::Verifier::Options limits;
  limits.max_depth = kFbMaxDepth;
  limits.max_tables = flatbuffers::uoffset_t(1 + len / 8);
  limits.check_alignment = kind == FbKind::Packet;
  flatbuffers::Verifier v(data, len, limits);
  if (!(prefixed ? v.VerifySizePrefixedBuffer<T>(ident) : v.VerifyBuffer<T>(ident)))
    throw FbError(0, "the '" + id + "' flatbuffer of " + std::to_string(len) +
                         " bytes fails verification (an offset, vtable, vector or string outside it" +
                         (kind == FbKind::Packet ? " or misaligned" : "") +
                         ", or tables nested or shared beyond the limits)");
  return prefixed ? flatbuffers::GetSizePrefixedRoot<T>(data) : flatbuffers::GetRoot<T>(data);
}

struct TableEntry {
  std::int64_t offset, t0, t1, n;
  std::int32_t stream, size;
};

class Aedat4Reader final : public EventReader {
 public:
  Aedat4Reader(const std::string& path, const ReaderOptions& o) : f_(path) {
    path_ = path;
    options_ = o;
    char magic[14];
    std::size_t got = f_.read(magic, 14);
    std::string m(magic, got);
    std::size_t hdr_at;
    if (m.rfind("#!AER-DAT4.0\r\n", 0) == 0) hdr_at = 14;
    else if (m.rfind("#!AER-DAT4.0\n", 0) == 0) hdr_at = 13;
    else f_.fail(0, "bad magic line: expected '#!AER-DAT4.0'");
    f_.seek(hdr_at);
    unsigned char sz[4];
    f_.readExact(sz, 4, "IOHeader size");
    const auto hsize = loadLE<std::int32_t>(sz);
    if (hsize < 8 || std::uint64_t(hsize) > f_.size() - f_.tell() || hsize > (64 << 20))
      f_.fail(hdr_at, "IOHeader size " + std::to_string(hsize) + " out of range");
    std::vector<unsigned char> hb(std::size_t(hsize) + 4);
    std::memcpy(hb.data(), sz, 4);
    f_.readExact(hb.data() + 4, std::size_t(hsize), "IOHeader");
    data_start_ = f_.tell();
    std::string xml;
    try {
      const auto* h = verifiedRoot<fbs::IoHeader>(hb.data(), hb.size(), "IOHE", FbKind::Header);
      compression_ = std::int32_t(h->compression());
      table_pos_ = h->data_table_position();
      const flatbuffers::String* info = h->info_node();
      if (info && reinterpret_cast<std::uintptr_t>(info) % alignof(flatbuffers::uoffset_t) != 0)
        throw FbError(std::size_t(reinterpret_cast<const unsigned char*>(info) - hb.data()),
                      "the stream description (string) is not 4-aligned");
      if (info) xml = info->str();
    } catch (const FbError& e) {
      f_.fail(hdr_at + e.offset, std::string("IOHeader: ") + e.what());
    }
    if (compression_ < 0 || compression_ > 4)
      f_.fail(hdr_at, "unknown compression " + std::to_string(compression_));
    if (table_pos_ >= 0 && std::uint64_t(table_pos_) < data_start_)
      f_.fail(hdr_at, "data table position " + std::to_string(table_pos_) + " outside the file");
    if (table_pos_ >= 0 && std::uint64_t(table_pos_) >= f_.size()) {
      // the file was cut before its data table: read the packets that are there
      warnTruncated(f_.size(), path_ + ": byte " + std::to_string(hdr_at) + ": the data table at byte " +
                                   std::to_string(table_pos_) + " is beyond the end of the file at byte " +
                                   std::to_string(f_.size()) + ": truncated, read without the table");
      table_pos_ = -1;
    }
    streams_ = parseStreams(xml);
    for (const auto& st : streams_)
      if (st.width > kMaxReaderSensorSide || st.height > kMaxReaderSensorSide)
        f_.fail(hdr_at, "stream " + std::to_string(st.id) + " declares a " + std::to_string(st.width) + "x" +
                            std::to_string(st.height) + " sensor (at most " + std::to_string(kMaxReaderSensorSide) +
                            "x" + std::to_string(kMaxReaderSensorSide) + ")");
    static const char* cnames[] = {"none", "LZ4", "LZ4 high", "Zstd", "Zstd high"};
    notes_.push_back(std::string("compression ") + cnames[compression_]);
    for (const auto& s : streams_) {
      notes_.push_back("stream " + std::to_string(s.id) + " " + printable(s.type, 16) +
                       (s.width ? " " + std::to_string(s.width) + "x" + std::to_string(s.height) : ""));
      if (s.type == "EVTS" && event_stream_ < 0) {
        event_stream_ = s.id;
        width_ = s.width;
        height_ = s.height;
      }
      if (s.type == "IMUS" && imu_stream_ < 0) imu_stream_ = s.id;
    }
    if (table_pos_ >= 0) notes_.push_back("file data table at byte " + std::to_string(table_pos_));
    if (o.width > 0) width_ = o.width;
    if (o.height > 0) height_ = o.height;
    f_.seek(data_start_);
  }
  Format format() const override { return Format::Aedat4; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    while (batch.size() < max) {
      if (cur_ == count_ && !nextPacket(true, nullptr)) break;
      drain(batch, max);
    }
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    Aedat4Reader other(path_, options_);
    std::vector<ImuSample> imu;
    while (other.nextPacket(false, &imu)) {
    }
    return imu;
  }

  bool seekTime(double t_start) override {
    if (!loadTable()) return false;
    if (std::isnan(t_start)) return false;
    const double t_clamped = std::clamp(std::floor(t_start * 1e6), -9.0e18, 9.0e18);
    const auto t_us = std::int64_t(t_clamped);
    for (const auto& e : table_) {
      if (e.stream != event_stream_) continue;
      if (e.t1 >= t_us) {
        f_.seek(std::uint64_t(e.offset) - 8);
        cur_ = count_ = 0;
        return true;
      }
    }
    f_.seek(end_of_packets());
    cur_ = count_ = 0;
    return true;
  }

 private:
  /// The file ends inside the packet at `at`: the complete packets before it are
  /// read; a counted warning (an error with `strict`) names both bytes.
  void truncatedAt(std::uint64_t at, const std::string& what) {
    warnTruncated(f_.size(), path_ + ": byte " + std::to_string(at) + ": " + what +
                                 " cut by the end of the file at byte " + std::to_string(f_.size()) +
                                 ": truncated, ignored");
    f_.seek(f_.size());
  }
  std::uint64_t end_of_packets() const { return table_pos_ >= 0 ? std::uint64_t(table_pos_) : f_.size(); }

  void drain(std::vector<Event>& batch, std::size_t max) {
    for (; cur_ < count_ && batch.size() < max; ++cur_) {
      // The verifier checks the vector's length word to 4 bytes, not the 8
      // its structs' int64 time needs: each struct is read from a copy.
      fbs::PolarityEvent p;
      std::memcpy(static_cast<void*>(&p), events_ + sizeof(p) * cur_, sizeof(p));
      const std::int64_t t = p.t_us();
      const std::int16_t x = p.x(), y = p.y();
      const bool on = p.on();
      auto where = [&] {
        return path_ + ": byte " + std::to_string(pkt_byte_) + " (packet), event " + std::to_string(cur_);
      };
      if (x < 0 || y < 0 || (width_ > 0 && x >= width_) || (height_ > 0 && y >= height_)) {
        outsideSensor(where(), double(x), double(y));
        continue;
      }
      if (t >= kMaxExactMicroseconds || t <= -kMaxExactMicroseconds)
        throw IoError(where() + ": timestamp " + std::to_string(t) +
                      " us beyond 2^33 s, where seconds in a double lose microseconds");
      Event e;
      e.t = double(t) / 1e6;  // correctly rounded: the same double as the text "S.UUUUUU"
      e.x = float(x);
      e.y = float(y);
      e.on = on;
      admit(batch, e, where);
    }
  }

  /// Decompresses `in` into out_ (bounded by max_packet_bytes).
  void decompress(const std::vector<unsigned char>& in, std::uint64_t at) {
    const std::size_t cap = options_.max_packet_bytes;
    if (compression_ == 0) {
      out_ = in;
      return;
    }
    out_.clear();
    if (compression_ == 1 || compression_ == 2) {
      LZ4F_dctx* ctx = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
        f_.fail(at, "cannot create an LZ4 context");
      std::size_t src = 0;
      std::size_t dst_used = 0;
      out_.resize(std::min(cap, std::max<std::size_t>(in.size() * 4, 1 << 16)));
      std::size_t ret = 1;
      while (src < in.size()) {
        if (dst_used == out_.size()) {
          if (out_.size() >= cap) {
            LZ4F_freeDecompressionContext(ctx);
            f_.fail(at, "LZ4 packet decompresses beyond the " + std::to_string(cap) + "-byte limit");
          }
          out_.resize(std::min(cap, out_.size() * 2));
        }
        std::size_t dst_len = out_.size() - dst_used;
        std::size_t src_len = in.size() - src;
        ret = LZ4F_decompress(ctx, out_.data() + dst_used, &dst_len, in.data() + src, &src_len, nullptr);
        if (LZ4F_isError(ret)) {
          std::string msg = LZ4F_getErrorName(ret);
          LZ4F_freeDecompressionContext(ctx);
          f_.fail(at, "corrupt LZ4 frame: " + msg);
        }
        src += src_len;
        dst_used += dst_len;
        if (ret == 0) break;
        if (src_len == 0 && dst_len == 0) break;
      }
      LZ4F_freeDecompressionContext(ctx);
      if (ret != 0) f_.fail(at, "truncated LZ4 frame");
      out_.resize(dst_used);
      return;
    }
    // Zstd
    ZSTD_DStream* ds = ZSTD_createDStream();
    ZSTD_initDStream(ds);
    // The frame header sizes the decoder's window (up to 128 MB by default):
    // bound it like the packet (a DV packet's frame fits its content). Found by
    // the aedat4_zstd fuzz target: a 98 MB window from a 3 KB file.
    ZSTD_DCtx_setParameter(ds, ZSTD_d_windowLogMax, kZstdWindowLogMax);
    ZSTD_inBuffer ib{in.data(), in.size(), 0};
    out_.resize(std::min(cap, std::max<std::size_t>(in.size() * 4, 1 << 16)));
    std::size_t used = 0;
    std::size_t ret = 1;
    while (true) {
      if (used == out_.size()) {
        if (out_.size() >= cap) {
          ZSTD_freeDStream(ds);
          f_.fail(at, "Zstd packet decompresses beyond the " + std::to_string(cap) + "-byte limit");
        }
        out_.resize(std::min(cap, out_.size() * 2));
      }
      ZSTD_outBuffer ob{out_.data(), out_.size(), used};
      ret = ZSTD_decompressStream(ds, &ob, &ib);
      used = ob.pos;
      if (ZSTD_isError(ret)) {
        std::string msg = ZSTD_getErrorName(ret);
        ZSTD_freeDStream(ds);
        f_.fail(at, "corrupt Zstd frame: " + msg);
      }
      if (ret == 0) break;
      if (ib.pos == ib.size && ob.pos < ob.size) break;  // input exhausted, frame incomplete
    }
    ZSTD_freeDStream(ds);
    if (ret != 0) f_.fail(at, "truncated Zstd frame");
    out_.resize(used);
  }

  /// Takes the decompressed packet in out_ (from byte `at`) as the current
  /// event packet; false when it holds no event. Throws FbError.
  bool loadEvents(std::uint64_t at) {
    const auto* events = verifiedRoot<fbs::EventPacket>(out_.data(), out_.size(), "EVTS", FbKind::Packet)->events();
    events_ = events ? events->Data() : nullptr;
    cur_ = 0;
    count_ = events ? events->size() : 0;
    pkt_byte_ = at;
    return count_ > 0;
  }

  /// Appends the samples of the decompressed IMU packet in out_ (from byte
  /// `at`) to `imu`. Throws FbError, or IoError for a non-finite value.
  void appendImu(std::uint64_t at, std::vector<ImuSample>& imu) {
    const auto* samples = verifiedRoot<fbs::ImuPacket>(out_.data(), out_.size(), "IMUS", FbKind::Packet)->samples();
    if (!samples) return;
    for (flatbuffers::uoffset_t i = 0; i < samples->size(); ++i) {
      const fbs::ImuSample* it = samples->Get(i);
      ImuSample s;
      s.t = double(it->t_us()) / 1e6;
      s.accel = Vec3(it->accel_x_g(), it->accel_y_g(), it->accel_z_g()) * kGravity;
      s.gyro = Vec3(it->gyro_x_dps(), it->gyro_y_dps(), it->gyro_z_dps()) * kDegToRad;
      if (!s.accel.allFinite() || !s.gyro.allFinite())
        f_.fail(at, "non-finite IMU value in sample " + std::to_string(i));
      imu.push_back(s);
    }
  }

  /// Reads packets until an event packet is loaded (want_events) or, for IMU
  /// collection, through every packet. Returns false at the end.
  bool nextPacket(bool want_events, std::vector<ImuSample>* imu) {
    while (true) {
      const std::uint64_t at = f_.tell();
      if (at >= end_of_packets()) return false;
      unsigned char h[8];
      if (end_of_packets() - at < 8) {
        truncatedAt(at, "packet header");
        return false;
      }
      f_.readExact(h, 8, "packet header");
      const auto stream = loadLE<std::int32_t>(h);
      const auto size = loadLE<std::int32_t>(h + 4);
      if (size <= 0)
        f_.fail(at, "packet size " + std::to_string(size) + " out of range: corrupt");
      if (std::uint64_t(size) > end_of_packets() - f_.tell()) {
        if (table_pos_ >= 0)  // a packet overlapping the data table is corrupt, not cut
          f_.fail(at, "packet size " + std::to_string(size) + " out of range (" +
                          std::to_string(end_of_packets() - f_.tell()) + " bytes left before the data table): corrupt");
        truncatedAt(at, "packet of " + std::to_string(size) + " bytes");
        return false;
      }
      if (std::size_t(size) > options_.max_packet_bytes)
        f_.fail(at, "packet size " + std::to_string(size) + " exceeds the limit");
      const bool is_events = stream == event_stream_ && want_events;
      const bool is_imu = stream == imu_stream_ && imu;
      if (!is_events && !is_imu) {
        f_.seek(f_.tell() + std::uint64_t(size));
        continue;
      }
      raw_.resize(std::size_t(size));
      f_.readExact(raw_.data(), raw_.size(), "packet");
      decompress(raw_, at);
      try {
        if (is_events) {
          if (loadEvents(at)) return true;
          continue;
        }
        appendImu(at, *imu);
      } catch (const FbError& e) {
        f_.fail(at, std::string("packet payload: ") + e.what());
      }
    }
  }

  bool loadTable() {
    if (table_loaded_) return !table_.empty();
    table_loaded_ = true;
    if (table_pos_ < 0) return false;
    const std::uint64_t keep = f_.tell();
    const std::uint64_t len = f_.size() - std::uint64_t(table_pos_);
    if (len == 0 || len > options_.max_packet_bytes) f_.fail(std::uint64_t(table_pos_), "data table size out of range");
    f_.seek(std::uint64_t(table_pos_));
    std::vector<unsigned char> raw(len);
    f_.readExact(raw.data(), raw.size(), "data table");
    decompress(raw, std::uint64_t(table_pos_));
    try {
      const auto* entries = verifiedRoot<fbs::DataTable>(out_.data(), out_.size(), "FTAB", FbKind::Packet)->entries();
      for (flatbuffers::uoffset_t i = 0; entries && i < entries->size(); ++i) {
        const fbs::DataTableEntry* d = entries->Get(i);
        TableEntry e;
        e.offset = d->payload_byte();
        e.stream = d->packet() ? d->packet()->stream_id() : -1;
        e.size = d->packet() ? d->packet()->size() : 0;
        e.n = d->elements();
        e.t0 = d->t_start_us();
        e.t1 = d->t_end_us();
        if (e.offset < std::int64_t(data_start_) + 8 || std::uint64_t(e.offset) > end_of_packets())
          throw FbError(0, "data table entry offset " + std::to_string(e.offset) + " outside the packets");
        table_.push_back(e);
      }
    } catch (const FbError& e) {
      f_.fail(std::uint64_t(table_pos_), std::string("data table: ") + e.what());
    }
    // Validate entries against the packet headers they point to.
    for (const auto& e : table_) {
      f_.seek(std::uint64_t(e.offset) - 8);
      unsigned char h[8];
      f_.readExact(h, 8, "packet header");
      if (loadLE<std::int32_t>(h) != e.stream || loadLE<std::int32_t>(h + 4) != e.size)
        f_.fail(std::uint64_t(e.offset) - 8, "data table entry does not match the packet header there");
    }
    f_.seek(keep);
    return !table_.empty();
  }

  BinFile f_;
  std::uint64_t data_start_ = 0;
  std::int32_t compression_ = 0;
  std::int64_t table_pos_ = -1;
  std::vector<StreamInfo> streams_;
  int event_stream_ = -1, imu_stream_ = -1;
  std::vector<unsigned char> raw_, out_;
  const unsigned char* events_ = nullptr;  ///< the current packet's fbs::PolarityEvent structs, in out_
  std::size_t cur_ = 0, count_ = 0;
  std::uint64_t pkt_byte_ = 0;
  bool table_loaded_ = false;
  std::vector<TableEntry> table_;
};

}  // namespace

std::unique_ptr<EventReader> openAedat4(const std::string& path, const ReaderOptions& o) {
  return std::make_unique<Aedat4Reader>(path, o);
}

}  // namespace celc::detail
