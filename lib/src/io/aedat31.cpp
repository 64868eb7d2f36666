// AEDAT 3.1 (cAER): '#' header lines up to "#!END-HEADER", then packets, each a
// 28-byte little-endian header
//   int16 eventType, int16 eventSource, int32 eventSize, int32 eventTSOffset,
//   int32 eventTSOverflow, int32 eventCapacity, int32 eventNumber, int32 eventValid
// followed by eventCapacity * eventSize bytes of events (the first eventNumber used).
// Timestamps: int32 [us] extended to 64 bits as (eventTSOverflow << 31) | ts.
//  - type 1 polarity, 8 bytes: uint32 data (bit 0 valid, bit 1 polarity (1 = ON),
//    bits 2..16 y, bits 17..31 x; origin top-left), int32 timestamp;
//  - type 3 IMU6, 36 bytes: uint32 info (bit 0 valid), int32 timestamp, float
//    accel x y z [g], float gyro x y z [deg/s], float temperature [C];
//  - type 4 IMU9, 48 bytes: as IMU6 plus a magnetometer (ignored).
// Other types (special, frames, ...) are skipped.
#include <algorithm>
#include <cmath>

#include "io/aedat_readers.hpp"
#include "io/binary_file.hpp"

namespace celc::detail {
namespace {

class Aedat31Reader final : public EventReader {
 public:
  Aedat31Reader(const std::string& path, const ReaderOptions& o) : f_(path) {
    path_ = path;
    options_ = o;
    std::string line;
    auto trim = [](std::string s) {
      while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
      return s;
    };
    if (!f_.readLine(line, 1024) || trim(line) != "#!AER-DAT3.1")
      f_.fail(0, "bad magic line: expected '#!AER-DAT3.1', found '" + printable(trim(line), 40) + "'");
    bool ended = false;
    while (f_.tell() < (std::uint64_t(16) << 20)) {
      std::uint64_t start = f_.tell();
      if (!f_.readLine(line, 1 << 20)) break;
      if (line.back() != '\n') f_.fail(start, "header line not terminated: truncated header");
      line = trim(line);
      if (line == "#!END-HEADER") {
        ended = true;
        break;
      }
      if (line.empty() || line[0] != '#') f_.fail(start, "header line does not start with '#'");
      if (line.rfind("#Source ", 0) == 0) {
        std::size_t colon = line.find(':');
        if (colon != std::string::npos) {
          std::string name = line.substr(colon + 1);
          while (!name.empty() && name.front() == ' ') name.erase(name.begin());
          notes_.push_back(printable("source" + line.substr(7, colon - 7) + ": " + name, 120));
          int w, h;
          if (width_ == 0 && sensorSizeFromChip(name, w, h)) width_ = w, height_ = h;
        }
      }
    }
    if (!ended) f_.fail(f_.tell(), "no '#!END-HEADER' line: truncated or not an AEDAT 3.1 file");
    data_start_ = f_.tell();
    if (o.width > 0) width_ = o.width;
    if (o.height > 0) height_ = o.height;
  }
  Format format() const override { return Format::Aedat31; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    decode(&batch, max, nullptr);
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    Aedat31Reader other(path_, options_);
    std::vector<ImuSample> imu;
    other.decode(nullptr, 0, &imu);
    return imu;
  }

  void decode(std::vector<Event>* events, std::size_t max, std::vector<ImuSample>* imu) {
    if (!started_) {
      f_.seek(data_start_);
      started_ = true;
    }
    while (true) {
      // drain the current polarity packet
      if (events && cur_ < count_) {
        const unsigned char* p = pkt_.data() + cur_ * 8;
        for (; cur_ < count_; ++cur_, p += 8) {
          const auto d = loadLE<std::uint32_t>(p);
          if ((d & 1u) == 0) continue;  // invalid event
          const auto ts = loadLE<std::int32_t>(p + 4);
          const std::int64_t t = (overflow_ << 31) | std::int64_t(std::uint32_t(ts) & 0x7FFFFFFFu);
          const std::uint32_t y = (d >> 2) & 0x7FFFu;
          const std::uint32_t x = (d >> 17) & 0x7FFFu;
          const std::uint64_t byte = pkt_byte_ + cur_ * 8;
          if ((width_ > 0 && x >= std::uint32_t(width_)) || (height_ > 0 && y >= std::uint32_t(height_))) {
            outsideSensor(path_ + ": byte " + std::to_string(byte), double(x), double(y));
            continue;
          }
          Event e;
          e.t = double(t) / 1e6;  // correctly rounded: the same double as the text "S.UUUUUU"
          e.x = float(x);
          e.y = float(y);
          e.on = (d & 2u) != 0;
          admit(*events, e, [&] { return path_ + ": byte " + std::to_string(byte); });
          if (events->size() >= max) {
            ++cur_;
            return;
          }
        }
      }
      if (!nextPacket(events != nullptr, imu)) return;
    }
  }

 private:
  /// Reads the next packet header; loads polarity payloads (when wanted) into pkt_,
  /// decodes IMU payloads into `imu` (when non-null), skips the rest.
  bool nextPacket(bool want_events, std::vector<ImuSample>* imu) {
    cur_ = count_ = 0;
    const std::uint64_t at = f_.tell();
    if (at == f_.size()) return false;
    unsigned char h[28];
    if (f_.size() - at < 28) {
      warnTruncated(f_.size(), path_ + ": byte " + std::to_string(at) +
                                   ": packet header cut by the end of the file at byte " +
                                   std::to_string(f_.size()) + ": truncated, ignored");
      f_.seek(f_.size());
      return false;
    }
    f_.readExact(h, 28, "packet header");
    const auto type = loadLE<std::int16_t>(h);
    const auto source = loadLE<std::int16_t>(h + 2);
    const auto size = loadLE<std::int32_t>(h + 4);
    const auto tsoff = loadLE<std::int32_t>(h + 8);
    const auto overflow = loadLE<std::int32_t>(h + 12);
    const auto capacity = loadLE<std::int32_t>(h + 16);
    const auto number = loadLE<std::int32_t>(h + 20);
    // 64-bit arithmetic: every field may hold INT32_MAX
    if (size <= 0 || capacity < 0 || number < 0 || number > capacity || overflow < 0 || tsoff < 0 ||
        std::int64_t(tsoff) + 4 > std::int64_t(size))
      f_.fail(at, "invalid packet header (type " + std::to_string(type) + ", size " + std::to_string(size) +
                      ", capacity " + std::to_string(capacity) + ", number " + std::to_string(number) + ")");
    // (overflow << 31) us reaches 2^33 s at overflow 4,000,000: seconds in a
    // double would no longer resolve microseconds (kMaxExactMicroseconds).
    if ((std::int64_t(overflow) << 31) + 0x7FFFFFFF >= kMaxExactMicroseconds)
      f_.fail(at, "eventTSOverflow " + std::to_string(overflow) + " puts the times at " +
                      std::to_string((std::int64_t(overflow) << 31) / 1000000) +
                      " s, beyond 2^33 s, where seconds in a double lose microseconds (a damaged header?)");
    const std::uint64_t bytes = std::uint64_t(size) * std::uint64_t(capacity);
    if (bytes > f_.size() - f_.tell()) {  // the last packet cut by the end of the file: the complete ones are read
      warnTruncated(f_.size(), path_ + ": byte " + std::to_string(at) + ": packet of " +
                                   std::to_string(bytes) + " bytes extends beyond the end of the file at byte " +
                                   std::to_string(f_.size()) + ": truncated, ignored");
      f_.seek(f_.size());
      return false;
    }
    if (bytes > options_.max_packet_bytes)
      f_.fail(at, "packet of " + std::to_string(bytes) + " bytes exceeds the limit");
    const std::uint64_t payload = f_.tell();
    const bool polarity = type == 1;
    const bool imu_type = type == 3 || type == 4;
    const std::size_t want_size = polarity ? 8 : (type == 3 ? 36 : 48);
    if ((polarity || imu_type) && std::size_t(size) != want_size)
      f_.fail(at, "event type " + std::to_string(type) + " with size " + std::to_string(size) +
                      " (expected " + std::to_string(want_size) + ")");
    if (options_.aedat_source >= 0 && source != options_.aedat_source) {
      f_.seek(payload + bytes);
      return true;
    }
    if (polarity && want_events) {
      pkt_.resize(std::size_t(number) * 8);
      f_.readExact(pkt_.data(), pkt_.size(), "polarity packet");
      f_.seek(payload + bytes);
      pkt_byte_ = payload;
      overflow_ = overflow;
      count_ = std::size_t(number);
      return true;
    }
    if (imu_type && imu) {
      std::vector<unsigned char> buf(std::size_t(number) * std::size_t(size));
      f_.readExact(buf.data(), buf.size(), "IMU packet");
      for (std::int32_t i = 0; i < number; ++i) {
        const unsigned char* p = buf.data() + std::size_t(i) * std::size_t(size);
        if ((loadLE<std::uint32_t>(p) & 1u) == 0) continue;
        const auto ts = loadLE<std::int32_t>(p + 4);
        ImuSample s;
        s.t = double((std::int64_t(overflow) << 31) | std::int64_t(std::uint32_t(ts) & 0x7FFFFFFFu)) / 1e6;
        float v[6];
        for (int k = 0; k < 6; ++k) v[k] = loadLE<float>(p + 8 + 4 * k);
        s.accel = Vec3(v[0], v[1], v[2]) * kGravity;
        s.gyro = Vec3(v[3], v[4], v[5]) * kDegToRad;
        if (!s.accel.allFinite() || !s.gyro.allFinite())
          f_.fail(payload + std::uint64_t(i) * std::uint64_t(size), "non-finite IMU value");
        imu->push_back(s);
      }
      f_.seek(payload + bytes);
      return true;
    }
    f_.seek(payload + bytes);
    return true;
  }

  BinFile f_;
  std::uint64_t data_start_ = 0;
  bool started_ = false;
  std::vector<unsigned char> pkt_;
  std::uint64_t pkt_byte_ = 0;
  std::int64_t overflow_ = 0;
  std::size_t cur_ = 0, count_ = 0;
};

}  // namespace

std::unique_ptr<EventReader> openAedat31(const std::string& path, const ReaderOptions& o) {
  return std::make_unique<Aedat31Reader>(path, o);
}

}  // namespace celc::detail
