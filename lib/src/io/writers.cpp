#include "celc/io/writers.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>

#include "io/binary_file.hpp"

namespace celc {
namespace {

class Out {
 public:
  explicit Out(const std::string& path) : path_(path) {
    f_ = std::fopen(path.c_str(), "wb");
    if (!f_) throw IoError(path + ": cannot create: " + std::strerror(errno));
  }
  ~Out() {
    if (f_) std::fclose(f_);
  }
  void put(const void* p, std::size_t n) {
    if (n && std::fwrite(p, 1, n, f_) != n) throw IoError(path_ + ": write error");
  }
  void put(const std::string& s) { put(s.data(), s.size()); }
  void close() {
    if (std::fclose(f_) != 0) throw IoError(path_ + ": write error on close");
    f_ = nullptr;
  }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
};

std::int64_t us(double t) { return std::llround(t * 1e6); }

void textLines(const std::string& path, const TextWriteOptions& o, std::size_t n,
               const std::function<int(std::size_t, char*, std::size_t)>& line) {
  Out out(path);
  const char* eol = o.crlf ? "\r\n" : "\n";
  if (!o.header.empty()) out.put("# " + o.header + eol);
  std::string buf;
  char tmp[512];
  for (std::size_t i = 0; i < n; ++i) {
    int len = 0;
    if (o.id_column) len = std::snprintf(tmp, sizeof(tmp), "%zu ", i);
    len += line(i, tmp + len, sizeof(tmp) - std::size_t(len));
    buf.append(tmp, std::size_t(len));
    if (i + 1 < n || o.final_newline) buf += eol;
    if (buf.size() > (1 << 20)) out.put(buf), buf.clear();
  }
  out.put(buf);
  out.close();
}

void putBE32(std::vector<unsigned char>& b, std::uint32_t v) {
  b.push_back((unsigned char)(v >> 24));
  b.push_back((unsigned char)(v >> 16));
  b.push_back((unsigned char)(v >> 8));
  b.push_back((unsigned char)v);
}
template <typename T>
void putLE(std::vector<unsigned char>& b, T v) {
  unsigned char tmp[sizeof(T)];
  std::memcpy(tmp, &v, sizeof(T));
  b.insert(b.end(), tmp, tmp + sizeof(T));
}
template <typename T>
void patchLE(std::vector<unsigned char>& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof(T));
}
void alignTo(std::vector<unsigned char>& b, std::size_t a) {
  while (b.size() % a) b.push_back(0);
}

std::int16_t quant(double v, double lsb) {
  const double r = std::round(v * lsb);
  return std::int16_t(std::clamp(r, -32768.0, 32767.0));
}

// ---- minimal flatbuffer building (forward layout, size-prefixed) ----------
/// Writes a vtable for `nfields` fields with the given offsets and returns its position.
std::size_t vtable(std::vector<unsigned char>& b, std::uint16_t table_size, const std::vector<std::uint16_t>& offs) {
  alignTo(b, 2);
  const std::size_t at = b.size();
  putLE<std::uint16_t>(b, std::uint16_t(4 + 2 * offs.size()));
  putLE<std::uint16_t>(b, table_size);
  for (auto o : offs) putLE<std::uint16_t>(b, o);
  return at;
}
/// Starts a table (8-aligned + 4 so that 8-byte fields at offset 8 align) with its soffset.
std::size_t tableStart(std::vector<unsigned char>& b, std::size_t vt) {
  alignTo(b, 8);
  const std::size_t at = b.size();
  putLE<std::int32_t>(b, std::int32_t(std::int64_t(at) - std::int64_t(vt)));
  return at;
}
/// Buffer header: size prefix, root offset (patched by finish), identifier.
std::vector<unsigned char> fbBegin(const char* ident) {
  std::vector<unsigned char> b(12, 0);
  std::memcpy(b.data() + 8, ident, 4);
  return b;
}
void fbFinish(std::vector<unsigned char>& b, std::size_t root) {
  patchLE<std::uint32_t>(b, 4, std::uint32_t(root - 4));
  patchLE<std::uint32_t>(b, 0, std::uint32_t(b.size() - 4));
}

std::vector<unsigned char> eventPacket(const Event* e, std::size_t n) {
  auto b = fbBegin("EVTS");
  const std::size_t vt = vtable(b, 8, {4});
  const std::size_t tb = tableStart(b, vt);
  const std::size_t slot = b.size();
  putLE<std::uint32_t>(b, 0);
  // vector: count at 8k+4 so that 16-byte elements start 8-aligned
  while (b.size() % 8 != 4) b.push_back(0);
  const std::size_t vec = b.size();
  patchLE<std::uint32_t>(b, slot, std::uint32_t(vec - slot));
  putLE<std::uint32_t>(b, std::uint32_t(n));
  for (std::size_t i = 0; i < n; ++i) {
    putLE<std::int64_t>(b, us(e[i].t));
    putLE<std::int16_t>(b, std::int16_t(e[i].x));
    putLE<std::int16_t>(b, std::int16_t(e[i].y));
    b.push_back(e[i].on ? 1 : 0);
    b.push_back(0), b.push_back(0), b.push_back(0);
  }
  fbFinish(b, tb);
  return b;
}

std::vector<unsigned char> imuPacket(const ImuSample* s, std::size_t n) {
  auto b = fbBegin("IMUS");
  const std::size_t vt = vtable(b, 8, {4});
  const std::size_t tb = tableStart(b, vt);
  const std::size_t slot = b.size();
  putLE<std::uint32_t>(b, 0);
  alignTo(b, 4);
  const std::size_t vec = b.size();
  patchLE<std::uint32_t>(b, slot, std::uint32_t(vec - slot));
  putLE<std::uint32_t>(b, std::uint32_t(n));
  const std::size_t slots = b.size();
  for (std::size_t i = 0; i < n; ++i) putLE<std::uint32_t>(b, 0);
  for (std::size_t i = 0; i < n; ++i) {
    // fields: 0 t@8, 1 temperature@16, 2..4 accel [g]@20.., 5..7 gyro [deg/s]@32..
    const std::size_t ivt = vtable(b, 44, {8, 16, 20, 24, 28, 32, 36, 40});
    const std::size_t it = tableStart(b, ivt);
    putLE<std::int32_t>(b, 0);  // padding to offset 8
    putLE<std::int64_t>(b, us(s[i].t));
    putLE<float>(b, 25.0f);
    for (int k = 0; k < 3; ++k) putLE<float>(b, float(s[i].accel[k] / detail::kGravity));
    for (int k = 0; k < 3; ++k) putLE<float>(b, float(s[i].gyro[k] / detail::kDegToRad));
    patchLE<std::uint32_t>(b, slots + 4 * i, std::uint32_t(it - (slots + 4 * i)));
  }
  fbFinish(b, tb);
  return b;
}

std::vector<unsigned char> compress(const std::vector<unsigned char>& in, Aedat4Compression c) {
  if (c == Aedat4Compression::None) return in;
  std::vector<unsigned char> out;
  if (c == Aedat4Compression::Lz4) {
    out.resize(LZ4F_compressFrameBound(in.size(), nullptr));
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
    if (LZ4F_isError(n)) throw IoError(std::string("LZ4 compression failed: ") + LZ4F_getErrorName(n));
    out.resize(n);
  } else {
    out.resize(ZSTD_compressBound(in.size()));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 1);
    if (ZSTD_isError(n)) throw IoError(std::string("Zstd compression failed: ") + ZSTD_getErrorName(n));
    out.resize(n);
  }
  return out;
}

}  // namespace

int formatEventLine(char* out, std::size_t cap, double t, int x, int y, bool on) {
  return std::snprintf(out, cap, "%.9f %d %d %d", t, x, y, on ? 1 : 0);
}

char* putEventLineMicros(char* p, std::int64_t t_us, int x, int y, bool on) {
  char* const end = p + kEventLineMicrosMaxChars;
  if (t_us < 0) {
    *p++ = '-';
    t_us = -t_us;
  }
  p = std::to_chars(p, end, static_cast<std::uint64_t>(t_us / 1000000)).ptr;
  *p++ = '.';
  std::int64_t frac = t_us % 1000000;
  for (std::int64_t d = 100000; d > 0; d /= 10) {
    *p++ = static_cast<char>('0' + frac / d);
    frac %= d;
  }
  *p++ = ' ';
  p = std::to_chars(p, end, x).ptr;
  *p++ = ' ';
  p = std::to_chars(p, end, y).ptr;
  *p++ = ' ';
  *p++ = on ? '1' : '0';
  return p;
}

void writeEventsText(const std::string& path, const std::vector<Event>& ev, const TextWriteOptions& o) {
  textLines(path, o, ev.size(), [&](std::size_t i, char* p, std::size_t cap) {
    return formatEventLine(p, cap, ev[i].t, int(ev[i].x), int(ev[i].y), ev[i].on);
  });
}

void writeImuText(const std::string& path, const std::vector<ImuSample>& imu, bool gyro_first,
                  const TextWriteOptions& o) {
  textLines(path, o, imu.size(), [&](std::size_t i, char* p, std::size_t cap) {
    const Vec3& a = gyro_first ? imu[i].gyro : imu[i].accel;
    const Vec3& b = gyro_first ? imu[i].accel : imu[i].gyro;
    return std::snprintf(p, cap, "%.9f %.9g %.9g %.9g %.9g %.9g %.9g", imu[i].t, a.x(), a.y(), a.z(), b.x(), b.y(),
                         b.z());
  });
}

void writePosesText(const std::string& path, const std::vector<PoseSample>& poses, const TextWriteOptions& o) {
  textLines(path, o, poses.size(), [&](std::size_t i, char* p, std::size_t cap) {
    const auto& s = poses[i];
    const auto& q = s.orientation;
    return std::snprintf(p, cap, "%.9f %.12g %.12g %.12g %.12g %.12g %.12g %.12g", s.t, s.position.x(),
                         s.position.y(), s.position.z(), q.x(), q.y(), q.z(), q.w());
  });
}

void writeAedat2(const std::string& path, const std::vector<Event>& events, const std::vector<ImuSample>& imu,
                 const std::string& chip, int gyro_dps, int accel_g) {
  int w = 0, h = 0;
  if (!detail::sensorSizeFromChip(chip, w, h)) throw IoError(path + ": unknown chip '" + chip + "'");
  Out out(path);
  out.put("#!AER-DAT2.0\r\n# This is a raw AE data file created by celc\r\n");
  out.put("# AEChip: eu.seebetter.ini.chips.davis." + chip + "\r\n");
  out.put("#Start of Preferences for this AEChip\r\n");
  out.put("#                <entry key=\"ImuGyroScale\" value=\"GyroFullScaleDegPerSec" + std::to_string(gyro_dps) +
          "\"/>\r\n");
  out.put("#                <entry key=\"ImuAccelScale\" value=\"ImuAccelScaleG" + std::to_string(accel_g) + "\"/>\r\n");
  out.put("#End of Preferences for this AEChip\r\n");
  // the nominal sensitivities the reader uses (MPU-6x50 datasheet values, as jAER)
  double glsb = 0, alsb = 0;
  switch (gyro_dps) {
    case 250: glsb = 131.0; break;
    case 500: glsb = 65.5; break;
    case 1000: glsb = 32.8; break;
    case 2000: glsb = 16.4; break;
    default: throw IoError(path + ": gyro full scale must be 250, 500, 1000 or 2000 deg/s");
  }
  switch (accel_g) {
    case 2: alsb = 16384.0; break;
    case 4: alsb = 8192.0; break;
    case 8: alsb = 4096.0; break;
    case 16: alsb = 2048.0; break;
    default: throw IoError(path + ": accel full scale must be 2, 4, 8 or 16 g");
  }
  std::vector<unsigned char> b;
  b.reserve(events.size() * 8 + imu.size() * 56);
  std::size_t j = 0;
  auto putImu = [&](const ImuSample& s) {
    const std::uint32_t t = std::uint32_t(us(s.t));
    std::int16_t v[7] = {quant(s.accel.x() / detail::kGravity, alsb), quant(s.accel.y() / detail::kGravity, alsb),
                         quant(s.accel.z() / detail::kGravity, alsb), 0,
                         quant(s.gyro.x() / detail::kDegToRad, glsb), quant(s.gyro.y() / detail::kDegToRad, glsb),
                         quant(s.gyro.z() / detail::kDegToRad, glsb)};
    for (std::uint32_t k = 0; k < 7; ++k) {
      putBE32(b, 0x80000C00u | (k << 28) | (std::uint32_t(std::uint16_t(v[k])) << 12));
      putBE32(b, t);
    }
  };
  for (const Event& e : events) {
    while (j < imu.size() && imu[j].t <= e.t) putImu(imu[j++]);
    const std::uint32_t y = std::uint32_t(h - 1 - int(e.y)), x = std::uint32_t(int(e.x));
    putBE32(b, (y << 22) | (x << 12) | (e.on ? 0x800u : 0u));
    putBE32(b, std::uint32_t(us(e.t)));
    if (b.size() > (8u << 20)) out.put(b.data(), b.size()), b.clear();
  }
  while (j < imu.size()) putImu(imu[j++]);
  out.put(b.data(), b.size());
  out.close();
}

void writeAedat31(const std::string& path, const std::vector<Event>& events, const std::vector<ImuSample>& imu,
                  const std::string& chip, int per_packet) {
  Out out(path);
  out.put("#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: " + chip + "\r\n#!END-HEADER\r\n");
  auto header = [](std::vector<unsigned char>& b, int16_t type, int32_t size, int32_t overflow, int32_t n) {
    putLE<std::int16_t>(b, type);
    putLE<std::int16_t>(b, 1);
    putLE<std::int32_t>(b, size);
    putLE<std::int32_t>(b, 4);
    putLE<std::int32_t>(b, overflow);
    putLE<std::int32_t>(b, n);
    putLE<std::int32_t>(b, n);
    putLE<std::int32_t>(b, n);
  };
  std::size_t j = 0;
  for (std::size_t i = 0, n = 0; i < events.size(); i += n) {
    n = std::min(events.size() - i, std::size_t(per_packet));
    // one timestamp overflow value per packet: cut the packet where it changes
    const std::int64_t ov = us(events[i].t) >> 31;
    for (std::size_t m = 1; m < n; ++m)
      if ((us(events[i + m].t) >> 31) != ov) {
        n = m;
        break;
      }
    // IMU samples up to this packet's first event, as one IMU6 packet
    std::size_t k = j;
    while (k < imu.size() && imu[k].t <= events[i].t) ++k;
    if (k > j) {
      std::vector<unsigned char> b;
      header(b, 3, 36, std::int32_t(us(imu[j].t) >> 31), std::int32_t(k - j));
      for (; j < k; ++j) {
        putLE<std::uint32_t>(b, 1);
        putLE<std::int32_t>(b, std::int32_t(us(imu[j].t) & 0x7FFFFFFF));
        for (int c = 0; c < 3; ++c) putLE<float>(b, float(imu[j].accel[c] / detail::kGravity));
        for (int c = 0; c < 3; ++c) putLE<float>(b, float(imu[j].gyro[c] / detail::kDegToRad));
        putLE<float>(b, 25.0f);
      }
      out.put(b.data(), b.size());
    }
    std::vector<unsigned char> b;
    header(b, 1, 8, std::int32_t(us(events[i].t) >> 31), std::int32_t(n));
    for (std::size_t m = i; m < i + n; ++m) {
      const Event& e = events[m];
      putLE<std::uint32_t>(b, (std::uint32_t(int(e.x)) << 17) | (std::uint32_t(int(e.y)) << 2) | (e.on ? 2u : 0u) | 1u);
      putLE<std::int32_t>(b, std::int32_t(us(e.t) & 0x7FFFFFFF));
    }
    out.put(b.data(), b.size());
  }
  if (j < imu.size()) {
    std::vector<unsigned char> b;
    header(b, 3, 36, std::int32_t(us(imu[j].t) >> 31), std::int32_t(imu.size() - j));
    for (; j < imu.size(); ++j) {
      putLE<std::uint32_t>(b, 1);
      putLE<std::int32_t>(b, std::int32_t(us(imu[j].t) & 0x7FFFFFFF));
      for (int c = 0; c < 3; ++c) putLE<float>(b, float(imu[j].accel[c] / detail::kGravity));
      for (int c = 0; c < 3; ++c) putLE<float>(b, float(imu[j].gyro[c] / detail::kDegToRad));
      putLE<float>(b, 25.0f);
    }
    out.put(b.data(), b.size());
  }
  out.close();
}

void writeAedat4(const std::string& path, const std::vector<Event>& events, const std::vector<ImuSample>& imu,
                 int width, int height, Aedat4Compression compression, int per_packet, bool data_table) {
  const char* cname = compression == Aedat4Compression::None ? "NONE"
                      : compression == Aedat4Compression::Lz4 ? "LZ4" : "ZSTD";
  const std::string xml =
      std::string("<dv version=\"2.0\">\n<node name=\"outInfo\" path=\"/mainloop/Recorder/outInfo/\">\n") +
      "<node name=\"0\" path=\"/mainloop/Recorder/outInfo/0/\">\n<attr key=\"compression\" type=\"string\">" + cname +
      "</attr>\n<attr key=\"typeIdentifier\" type=\"string\">EVTS</attr>\n"
      "<node name=\"info\" path=\"/mainloop/Recorder/outInfo/0/info/\">\n<attr key=\"sizeX\" type=\"int\">" +
      std::to_string(width) + "</attr>\n<attr key=\"sizeY\" type=\"int\">" + std::to_string(height) +
      "</attr>\n</node>\n</node>\n<node name=\"1\" path=\"/mainloop/Recorder/outInfo/1/\">\n"
      "<attr key=\"typeIdentifier\" type=\"string\">IMUS</attr>\n</node>\n</node>\n</dv>\n";
  // packets first (to know the data table position)
  struct Entry {
    std::int64_t offset, n, t0, t1;
    std::int32_t stream, size;
  };
  std::vector<std::vector<unsigned char>> packets;
  std::vector<Entry> entries;
  std::size_t j = 0;
  auto addPacket = [&](std::int32_t stream, std::vector<unsigned char> payload, std::int64_t n, std::int64_t t0,
                       std::int64_t t1) {
    auto c = compress(payload, compression);
    entries.push_back({0, n, t0, t1, stream, std::int32_t(c.size())});
    packets.push_back(std::move(c));
  };
  for (std::size_t i = 0; i < events.size(); i += std::size_t(per_packet)) {
    const std::size_t n = std::min(events.size() - i, std::size_t(per_packet));
    std::size_t k = j;
    while (k < imu.size() && imu[k].t <= events[i + n - 1].t) ++k;
    if (k > j) addPacket(1, imuPacket(imu.data() + j, k - j), std::int64_t(k - j), us(imu[j].t), us(imu[k - 1].t));
    j = k;
    addPacket(0, eventPacket(events.data() + i, n), std::int64_t(n), us(events[i].t), us(events[i + n - 1].t));
  }
  if (j < imu.size())
    addPacket(1, imuPacket(imu.data() + j, imu.size() - j), std::int64_t(imu.size() - j), us(imu[j].t),
              us(imu.back().t));
  // IOHeader: 0 compression int32, 1 dataTablePosition int64, 2 infoNode string
  auto header = [&](std::int64_t table_pos) {
    auto b = fbBegin("IOHE");
    const std::size_t vt = vtable(b, 20, {4, 8, 16});
    const std::size_t tb = tableStart(b, vt);
    putLE<std::int32_t>(b, std::int32_t(compression));
    putLE<std::int64_t>(b, table_pos);
    const std::size_t slot = b.size();
    putLE<std::uint32_t>(b, 0);
    const std::size_t str = b.size();
    patchLE<std::uint32_t>(b, slot, std::uint32_t(str - slot));
    putLE<std::uint32_t>(b, std::uint32_t(xml.size()));
    b.insert(b.end(), xml.begin(), xml.end());
    b.push_back(0);
    alignTo(b, 4);
    fbFinish(b, tb);
    return b;
  };
  const std::size_t header_size = header(-1).size();
  std::int64_t pos = 14 + std::int64_t(header_size);
  for (std::size_t i = 0; i < packets.size(); ++i) {
    entries[i].offset = pos + 8;  // DV convention: the payload's offset
    pos += 8 + std::int64_t(packets[i].size());
  }
  Out out(path);
  out.put("#!AER-DAT4.0\r\n");
  const auto hb = header(data_table ? pos : -1);
  out.put(hb.data(), hb.size());
  for (std::size_t i = 0; i < packets.size(); ++i) {
    std::vector<unsigned char> ph;
    putLE<std::int32_t>(ph, entries[i].stream);
    putLE<std::int32_t>(ph, entries[i].size);
    out.put(ph.data(), ph.size());
    out.put(packets[i].data(), packets[i].size());
  }
  if (data_table) {
    auto b = fbBegin("FTAB");
    const std::size_t vt = vtable(b, 8, {4});
    const std::size_t tb = tableStart(b, vt);
    const std::size_t slot = b.size();
    putLE<std::uint32_t>(b, 0);
    const std::size_t vec = b.size();
    patchLE<std::uint32_t>(b, slot, std::uint32_t(vec - slot));
    putLE<std::uint32_t>(b, std::uint32_t(entries.size()));
    const std::size_t slots = b.size();
    for (std::size_t i = 0; i < entries.size(); ++i) putLE<std::uint32_t>(b, 0);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const std::size_t evt = vtable(b, 48, {8, 16, 24, 32, 40});
      const std::size_t et = tableStart(b, evt);
      putLE<std::int32_t>(b, 0);
      putLE<std::int64_t>(b, entries[i].offset);
      putLE<std::int32_t>(b, entries[i].stream);
      putLE<std::int32_t>(b, entries[i].size);
      putLE<std::int64_t>(b, entries[i].n);
      putLE<std::int64_t>(b, entries[i].t0);
      putLE<std::int64_t>(b, entries[i].t1);
      patchLE<std::uint32_t>(b, slots + 4 * i, std::uint32_t(et - (slots + 4 * i)));
    }
    fbFinish(b, tb);
    const auto c = compress(b, compression);
    out.put(c.data(), c.size());
  }
  out.close();
}

}  // namespace celc
