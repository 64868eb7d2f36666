// AEDAT 2.0 (jAER): '#' header lines, then big-endian (uint32 address, int32
// timestamp [us]) pairs. DAVIS address layout:
//   bit 31 = 0: DVS event; bit 10 set = external (special) event;
//               x = bits 12..21, y = bits 22..30 (origin bottom-left), polarity = bit 11 (1 = ON)
//   bit 31 = 1: APS sample, or an IMU word when bits 10..11 are both set;
//               IMU word: index = bits 28..30 (0 ax, 1 ay, 2 az, 3 temperature,
//               4 gx, 5 gy, 6 gz), value = int16 in bits 12..27; seven words per sample.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "io/aedat_readers.hpp"
#include "io/binary_file.hpp"

namespace celc::detail {
namespace {

struct Aedat2Header {
  std::uint64_t data_start = 0;
  std::string chip;
  double gyro_lsb_per_dps = 32.8;   // jAER default: 1000 deg/s full scale
  double accel_lsb_per_g = 4096.0;  // jAER default: 8 g full scale
  std::uint64_t lines = 0;
};

std::string trimEol(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

int trailingInt(const std::string& s) {
  std::size_t e = s.size();
  std::size_t b = e;
  while (b > 0 && std::isdigit(static_cast<unsigned char>(s[b - 1]))) --b;
  if (b == e || e - b > 6) return -1;
  return std::stoi(s.substr(b, e - b));
}

/// value="..." of a preferences entry with key `key` on this line, or "".
std::string prefValue(const std::string& line, const std::string& key) {
  std::size_t k = line.find("key=\"" + key + "\"");
  if (k == std::string::npos) return {};
  std::size_t v = line.find("value=\"", k);
  if (v == std::string::npos) return {};
  v += 7;
  std::size_t e = line.find('"', v);
  if (e == std::string::npos) return {};
  return line.substr(v, e - v);
}

Aedat2Header readHeader(BinFile& f, const ReaderOptions& o) {
  Aedat2Header h;
  std::string line;
  if (!f.readLine(line, 1024) || trimEol(line) != "#!AER-DAT2.0")
    f.fail(0, "bad magic line: expected '#!AER-DAT2.0', found '" + printable(trimEol(line), 40) + "'");
  h.lines = 1;
  bool prefs_open = false;
  const std::uint64_t max_header = std::uint64_t(64) << 20;
  while (true) {
    std::uint64_t start = f.tell();
    unsigned char c;
    if (f.read(&c, 1) == 0) {
      if (prefs_open)
        f.fail(f.size(), "file ends inside the header (preferences block not closed, no event data): truncated");
      h.data_start = f.size();
      return h;
    }
    if (c != '#') {
      f.seek(start);
      h.data_start = start;
      break;
    }
    f.seek(start);
    if (!f.readLine(line, 1 << 20)) break;
    // The first data word may begin with the byte '#' (a DVS event with raw y in
    // 140..143 on a DAVIS240): header lines are text, so a "line" holding control
    // bytes other than tab / CR / LF is data.
    if (std::any_of(line.begin(), line.end(), [](char ch) {
          const auto u = static_cast<unsigned char>(ch);
          return u < 0x20 && u != '\t' && u != '\r' && u != '\n';
        })) {
      f.seek(start);
      h.data_start = start;
      break;
    }
    ++h.lines;
    if (f.tell() > max_header) f.fail(start, "header longer than 64 MB");
    if (line.back() != '\n') {
      if (f.tell() >= f.size())
        f.fail(f.size(), "file ends inside the header line " + std::to_string(h.lines) + " (no event data): truncated");
      f.fail(start, "header line longer than 1 MB");
    }
    line = trimEol(line);
    if (line.rfind("# AEChip:", 0) == 0 || line.rfind("#AEChip:", 0) == 0) {
      std::string chip = line.substr(line.find(':') + 1);
      std::size_t dot = chip.find_last_of('.');
      if (dot != std::string::npos) chip = chip.substr(dot + 1);
      while (!chip.empty() && chip.front() == ' ') chip.erase(chip.begin());
      h.chip = chip;
    }
    if (line.find("#Start of Preferences") == 0) prefs_open = true;
    if (line.find("#End of Preferences") == 0) prefs_open = false;
    std::string g = prefValue(line, "ImuGyroScale");
    if (!g.empty()) {
      switch (trailingInt(g)) {
        case 250: h.gyro_lsb_per_dps = 131.0; break;
        case 500: h.gyro_lsb_per_dps = 65.5; break;
        case 1000: h.gyro_lsb_per_dps = 32.8; break;
        case 2000: h.gyro_lsb_per_dps = 16.4; break;
        default: f.fail(start, "unknown ImuGyroScale '" + g + "'");
      }
    }
    std::string a = prefValue(line, "ImuAccelScale");
    if (!a.empty()) {
      switch (trailingInt(a)) {
        case 2: h.accel_lsb_per_g = 16384.0; break;
        case 4: h.accel_lsb_per_g = 8192.0; break;
        case 8: h.accel_lsb_per_g = 4096.0; break;
        case 16: h.accel_lsb_per_g = 2048.0; break;
        default: f.fail(start, "unknown ImuAccelScale '" + a + "'");
      }
    }
  }
  (void)o;
  return h;
}

class Aedat2Reader final : public EventReader {
 public:
  Aedat2Reader(const std::string& path, const ReaderOptions& o) : f_(path) {
    path_ = path;
    options_ = o;
    h_ = readHeader(f_, o);
    int w = 0, hh = 0;
    if (!h_.chip.empty() && sensorSizeFromChip(h_.chip, w, hh)) {
      width_ = w;
      height_ = hh;
    }
    if (o.width > 0) width_ = o.width;
    if (o.height > 0) height_ = o.height;
    std::string chip_upper;
    for (char c : h_.chip) chip_upper.push_back(char(std::toupper(static_cast<unsigned char>(c))));
    if (chip_upper.find("DVS128") != std::string::npos)
      f_.fail(0, "chip '" + printable(h_.chip, 60) + "' uses the DVS128 address layout, which is not supported (DAVIS only)");
    if (height_ <= 0)
      f_.fail(0, "sensor size unknown (chip '" + printable(h_.chip, 60) +
                     "'): give the width and height (needed to flip y to a top-left origin)");
    jump_us_ = std::int64_t(std::min(o.max_time_jump * 1e6, 2.0e9));
    notes_.push_back("chip " + (h_.chip.empty() ? std::string("unknown") : printable(h_.chip, 60)));
    notes_.push_back("header " + std::to_string(h_.lines) + " lines, data at byte " +
                     std::to_string(h_.data_start));
    char scale[96];
    std::snprintf(scale, sizeof(scale), "IMU scale %g LSB/(deg/s), %g LSB/g", h_.gyro_lsb_per_dps,
                  h_.accel_lsb_per_g);
    notes_.push_back(scale);
    // 8 MB blocks, or the data of a smaller file (rounded up to whole records)
    const std::uint64_t data = f_.size() - h_.data_start;
    buf_.resize(std::size_t(std::min<std::uint64_t>(std::uint64_t(8) << 20, std::max<std::uint64_t>((data + 7) / 8 * 8, 4096))));
  }
  Format format() const override { return Format::Aedat2; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    batch.reserve(std::min<std::size_t>(max, std::size_t(1) << 20));
    decode(&batch, max, nullptr);
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    Aedat2Reader other(path_, options_);
    std::vector<ImuSample> imu;
    other.decode(nullptr, 0, &imu);
    return imu;
  }

  /// Decodes until `max` events are in `events` (when non-null) or the end;
  /// IMU samples go to `imu` when non-null.
  void decode(std::vector<Event>* events, std::size_t max, std::vector<ImuSample>* imu) {
    const std::uint32_t h1 = std::uint32_t(height_ - 1);
    while (true) {
      if (pos_ == len_) {
        if (!refill()) return;
      }
      const unsigned char* p = buf_.data() + pos_;
      const std::size_t n = (len_ - pos_) / 8;
      std::size_t i = 0;
      for (; i < n; ++i, p += 8) {
        const std::uint32_t a = loadBE32(p);
        const std::uint32_t traw = loadBE32(p + 4);
        const std::int64_t t = unwrap(traw);
        if ((a & 0x80000000u) == 0) {
          if (a & 0x400u) {  // external input (special) event
            ++special_;
            continue;
          }
          if (!events) continue;
          const std::uint32_t x = (a >> 12) & 0x3FFu;
          const std::uint32_t yr = (a >> 22) & 0x1FFu;
          if (x >= std::uint32_t(width_) || yr > h1) {
            outsideSensor(path_ + ": byte " + std::to_string(byteOf(p)), double(x), double(yr));
            continue;
          }
          Event e;
          e.t = double(t) / 1e6;  // correctly rounded: the same double as the text "S.UUUUUU"
          e.x = float(x);
          e.y = float(h1 - yr);
          e.on = (a & 0x800u) != 0;
          admit(*events, e, [&] { return path_ + ": byte " + std::to_string(byteOf(p)); });
          if (events->size() >= max) {
            pos_ += (i + 1) * 8;
            return;
          }
        } else if ((a & 0xC00u) == 0xC00u) {
          if (!imu) continue;
          const int idx = int((a >> 28) & 7u);
          const auto v = std::int16_t(std::uint16_t((a >> 12) & 0xFFFFu));
          if (idx != imu_next_) {
            ++imu_broken_;
            imu_next_ = 0;
            if (idx != 0) continue;
          }
          if (idx == 0) imu_t_ = t;
          imu_raw_[idx] = v;
          imu_next_ = idx + 1;
          if (imu_next_ == 7) {
            ImuSample s;
            s.t = double(imu_t_) / 1e6;
            const double ka = kGravity / h_.accel_lsb_per_g;
            const double kg = kDegToRad / h_.gyro_lsb_per_dps;
            s.accel = Vec3(imu_raw_[0] * ka, imu_raw_[1] * ka, imu_raw_[2] * ka);
            s.gyro = Vec3(imu_raw_[4] * kg, imu_raw_[5] * kg, imu_raw_[6] * kg);
            imu->push_back(s);
            imu_next_ = 0;
          }
        }
        // other bit-31 words: APS samples, ignored
      }
      pos_ += n * 8;
    }
  }

 private:
  std::uint64_t byteOf(const unsigned char* p) const {
    return buf_start_ + std::uint64_t(p - buf_.data());
  }
  /// 64-bit time of a raw 32-bit timestamp. A wrap-around is recognised only
  /// when it is plausible: the timestamp continues, within max_time_jump, from
  /// the last trusted time across 2^32 us. A raw value far from the trusted time
  /// (one corrupt word such as 0xFFFFFFFF) is not unwrapped and does not move
  /// the trusted time unless the next word confirms it (a gap); admit() then
  /// reports it as an outlier or a gap. The first word is trusted only once
  /// another agrees with it: a corrupt first word (0xFFFFFFFF) does not make
  /// the good words that follow a wrap-around.
  std::int64_t unwrap(std::uint32_t raw) {
    const std::int64_t here = wrap_ + std::int64_t(raw);
    if (!have_raw_) {
      have_raw_ = true;
      ref_ = here;
      return here;
    }
    const std::int64_t wrapped = here + (std::int64_t(1) << 32);
    if (std::llabs(here - ref_) <= jump_us_ || (have_cand_ && std::llabs(here - cand_) <= jump_us_)) {
      ref_ = here;
      have_cand_ = false;
      confirmed_ = true;
      return here;
    }
    if (confirmed_ &&
        (std::llabs(wrapped - ref_) <= jump_us_ || (have_cand_ && std::llabs(wrapped - cand_) <= jump_us_))) {
      wrap_ += std::int64_t(1) << 32;
      ref_ = wrapped;
      have_cand_ = false;
      return wrapped;
    }
    cand_ = here;  // far from the trusted time: trusted only if the next word agrees
    have_cand_ = true;
    return here;
  }
  bool refill() {
    if (!started_) {
      f_.seek(h_.data_start);
      started_ = true;
    }
    buf_start_ = f_.tell();
    const std::size_t got = f_.read(buf_.data(), buf_.size());
    if (got == 0) return false;
    len_ = got - got % 8;
    pos_ = 0;
    if (got % 8 != 0) {
      if (f_.tell() < f_.size()) f_.fail(f_.tell(), "internal: unaligned read");
      if (len_ == 0) {  // only the partial record is left: the complete ones are read
        warnTruncated(f_.size(),
             path_ + ": byte " + std::to_string(buf_start_) + ": truncated event record: the file ends at byte " +
                 std::to_string(f_.size()) + ", " + std::to_string(got) + " trailing bytes ignored (records are 8 bytes)");
        return false;
      }
      // leave the partial record for the next refill, which reports it
      f_.seek(buf_start_ + len_);
    }
    return true;
  }

  BinFile f_;
  Aedat2Header h_;
  std::vector<unsigned char> buf_;
  std::uint64_t buf_start_ = 0;
  std::size_t pos_ = 0, len_ = 0;
  bool started_ = false;
  bool have_raw_ = false;
  bool confirmed_ = false;  ///< two words have agreed on the trusted time
  std::int64_t wrap_ = 0;
  std::int64_t ref_ = 0;   ///< last trusted unwrapped time [us]
  std::int64_t cand_ = 0;  ///< a time far from ref_, trusted when the next word agrees [us]
  bool have_cand_ = false;
  std::int64_t jump_us_ = 0;
  std::uint64_t special_ = 0, imu_broken_ = 0;
  int imu_next_ = 0;
  std::int64_t imu_t_ = 0;
  std::int16_t imu_raw_[7] = {0, 0, 0, 0, 0, 0, 0};
};

}  // namespace

std::unique_ptr<EventReader> openAedat2(const std::string& path, const ReaderOptions& o) {
  return std::make_unique<Aedat2Reader>(path, o);
}

}  // namespace celc::detail
