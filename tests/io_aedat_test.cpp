// AEDAT 2.0 / 3.1 / 4.0 readers: round trips through the writers, corrupted and
// hostile files, and conformance with the real recordings in ../shared/data.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "celc/io/window_source.hpp"
#include "celc/io/writers.hpp"
#include "io_test_util.hpp"

using namespace celc;
using namespace celc;
using celc::test::Place;
using celc::test::putBE32;
using celc::test::putLE32;
using celc::test::readBytes;
using celc::test::strictOptions;
using celc::test::TempDir;
using celc::test::writeBytes;
using celc::test::patchBytes;

namespace {

void expectSameEvents(const std::vector<Event>& a, const std::vector<Event>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_NEAR(a[i].t, b[i].t, 1e-9) << i;  // whole microseconds on both sides
    ASSERT_EQ(a[i].x, b[i].x) << i;
    ASSERT_EQ(a[i].y, b[i].y) << i;
    ASSERT_EQ(a[i].on, b[i].on) << i;
  }
}

/// IMU equality within the file's resolution.
void expectSameImu(const std::vector<ImuSample>& a, const std::vector<ImuSample>& b, double gyro_tol,
                   double accel_tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_NEAR(a[i].t, b[i].t, 1e-9) << i;
    ASSERT_LT((a[i].gyro - b[i].gyro).cwiseAbs().maxCoeff(), gyro_tol) << i;
    ASSERT_LT((a[i].accel - b[i].accel).cwiseAbs().maxCoeff(), accel_tol) << i;
  }
}

constexpr double kDeg = M_PI / 180.0;
constexpr double kG = 9.80665;

struct Fixture {
  std::vector<Event> ev;
  std::vector<ImuSample> imu;
};
Fixture fixture(std::size_t n = 20000, int w = 240, int h = 180, double t0 = 10.0) {
  Fixture f;
  f.ev = celc::test::randomEvents(n, w, h, 11, t0);
  f.imu = celc::test::randomImu(f.ev.front().t, f.ev.back().t, 12);
  return f;
}

}  // namespace

TEST(IoAedat, Aedat2RoundTrip) {
  TempDir d;
  auto f = fixture();
  writeAedat2(d.file("a.aedat"), f.ev, f.imu);
  EXPECT_EQ(detectFormat(d.file("a.aedat")), Format::Aedat2);
  auto r = openEventSource(d.file("a.aedat"));
  EXPECT_EQ(r->width(), 240);
  EXPECT_EQ(r->height(), 180);
  expectSameEvents(readAllEvents(*r), f.ev);
  // half an LSB: 0.5 / 32.8 deg/s and 0.5 / 4096 g
  expectSameImu(r->readImu(), f.imu, 0.51 / 32.8 * kDeg, 0.51 / 4096 * kG);
  EXPECT_EQ(r->warnings().total(), 0u);
}

TEST(IoAedat, Aedat2FullScaleFromHeaderAndDavis346) {
  TempDir d;
  auto f = fixture(3000, 346, 260);
  writeAedat2(d.file("a.aedat"), f.ev, f.imu, "DAVIS346B", 2000, 16);
  auto r = openEventSource(d.file("a.aedat"));
  EXPECT_EQ(r->width(), 346);
  EXPECT_EQ(r->height(), 260);
  expectSameEvents(readAllEvents(*r), f.ev);
  expectSameImu(r->readImu(), f.imu, 0.51 / 16.4 * kDeg, 0.51 / 2048 * kG);
}

TEST(IoAedat, Aedat2FirstDataByteIsHash) {
  TempDir d;
  // raw y = 179 - 37 = 142: the address's first byte is 0x23 = '#'
  std::vector<Event> ev = {{1.0, 5.0f, 37.0f, true}, {1.5, 6.0f, 38.0f, false}};
  writeAedat2(d.file("h.aedat"), ev, {});
  const std::string b = celc::test::readBytes(d.file("h.aedat"));
  ASSERT_EQ(b[b.size() - 16], '#');
  auto r = openEventSource(d.file("h.aedat"));
  expectSameEvents(readAllEvents(*r), ev);
}

TEST(IoAedat, Aedat2TimestampWrapIsUnwrapped) {
  TempDir d;
  auto ev = celc::test::randomEvents(40000, 240, 180, 5, 4294.96);  // crosses 2^32 us
  ASSERT_GT(ev.back().t, 4294.967296);
  writeAedat2(d.file("w.aedat"), ev, {});
  auto r = openEventSource(d.file("w.aedat"));
  expectSameEvents(readAllEvents(*r), ev);
  EXPECT_EQ(r->warnings().backwards_time, 0u);
}

TEST(IoAedat, Aedat31RoundTripWithOverflow) {
  TempDir d;
  auto f = fixture(20000, 240, 180, 2147.47);  // crosses 2^31 us: tsOverflow 0 -> 1
  ASSERT_GT(f.ev.back().t, 2147.483648);
  writeAedat31(d.file("a.aedat31"), f.ev, f.imu, "DAVIS240C", 1000);
  auto r = openEventSource(d.file("a.aedat31"));
  EXPECT_EQ(r->format(), Format::Aedat31);
  EXPECT_EQ(r->width(), 240);
  expectSameEvents(readAllEvents(*r), f.ev);
  // float32 in g and deg/s
  auto imu = r->readImu();
  ASSERT_EQ(imu.size(), f.imu.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    EXPECT_LT((imu[i].gyro - f.imu[i].gyro).norm(), 1e-5);
    EXPECT_LT((imu[i].accel - f.imu[i].accel).norm(), 1e-4);
  }
}

TEST(IoAedat, Aedat31SourceFilter) {
  TempDir d;
  auto f = fixture(1000);
  writeAedat31(d.file("a.aedat31"), f.ev, {}, "DAVIS240C", 100);
  ReaderOptions o;
  o.aedat_source = 2;  // the writer uses source 1
  auto r = openEventSource(d.file("a.aedat31"), o);
  EXPECT_TRUE(readAllEvents(*r).empty());
  o.aedat_source = 1;
  auto r1 = openEventSource(d.file("a.aedat31"), o);
  EXPECT_EQ(readAllEvents(*r1).size(), 1000u);
}

// The parameter: the packets' compression.
class IoAedat4Compression : public ::testing::TestWithParam<Aedat4Compression> {};

TEST_P(IoAedat4Compression, Aedat4RoundTripEveryCompression) {
  TempDir d;
  auto f = fixture(30000, 320, 240);
  {
    const Aedat4Compression c = GetParam();
    const std::string p = d.file("a" + std::to_string(int(c)) + ".aedat4");
    writeAedat4(p, f.ev, f.imu, 320, 240, c, 4096, true);
    auto r = openEventSource(p);
    EXPECT_EQ(r->format(), Format::Aedat4);
    EXPECT_EQ(r->width(), 320);
    EXPECT_EQ(r->height(), 240);
    expectSameEvents(readAllEvents(*r), f.ev);
    auto imu = r->readImu();
    ASSERT_EQ(imu.size(), f.imu.size());
    for (std::size_t i = 0; i < imu.size(); ++i) {
      EXPECT_LT((imu[i].gyro - f.imu[i].gyro).norm(), 1e-5);
      EXPECT_LT((imu[i].accel - f.imu[i].accel).norm(), 1e-4);
    }
  }
}
INSTANTIATE_TEST_SUITE_P(Packets, IoAedat4Compression,
                         ::testing::Values(Aedat4Compression::None, Aedat4Compression::Lz4, Aedat4Compression::Zstd),
                         [](const ::testing::TestParamInfo<Aedat4Compression>& i) {
                           return std::string(i.param == Aedat4Compression::None ? "none"
                                              : i.param == Aedat4Compression::Lz4 ? "lz4"
                                                                                  : "zstd");
                         });

TEST(IoAedat, Aedat4SeekWithDataTable) {
  TempDir d;
  auto f = fixture(50000, 320, 240);
  writeAedat4(d.file("t.aedat4"), f.ev, {}, 320, 240, Aedat4Compression::Lz4, 1000, true);
  writeAedat4(d.file("n.aedat4"), f.ev, {}, 320, 240, Aedat4Compression::Lz4, 1000, false);
  const double ts = f.ev[37777].t;
  auto r = openEventSource(d.file("t.aedat4"));
  ASSERT_TRUE(r->seekTime(ts));
  auto rest = readAllEvents(*r);
  // it skipped whole packets before the one holding ts, and nothing at or after ts
  EXPECT_EQ(rest.size(), 50000u - 37000u);  // packets of 1000: from the one holding event 37777
  std::size_t after = 0;
  for (const auto& e : f.ev) after += e.t >= ts;
  std::size_t got_after = 0;
  for (const auto& e : rest) got_after += e.t >= ts;
  EXPECT_EQ(got_after, after);
  auto r2 = openEventSource(d.file("n.aedat4"));
  EXPECT_FALSE(r2->seekTime(ts));  // no table: the window source filters instead
  // window source with a time range gives the same events either way
  for (const auto& p : {d.file("t.aedat4"), d.file("n.aedat4")}) {
    auto rr = openEventSource(p);
    WindowOptions wo;
    wo.events_per_window = 500;
    wo.t_start = ts;
    WindowSource ws(*rr, wo);
    EventWindow w;
    ASSERT_TRUE(ws.next(w));
    EXPECT_EQ(w.events.front().t, ts);
  }
}

// ---- bad input -----------------------------------------------------------------

TEST(IoAedatBad, BadMagicLines) {
  TempDir d;
  celc::test::writeBytes(d.file("a.aedat"), "#!AER-DAT9.9\r\n");
  EXPECT_IO_ERROR(openEventSource(d.file("a.aedat")), "byte 0", "unsupported AEDAT version");
  auto f = fixture(100);
  writeAedat2(d.file("b.aedat"), f.ev, {});
  std::string b = celc::test::readBytes(d.file("b.aedat"));
  b[10] = '1';  // "#!AER-DAT1.0" is not 2.0
  celc::test::writeBytes(d.file("b.aedat"), b);
  EXPECT_IO_ERROR(openEventSource(d.file("b.aedat")), "byte 0", "unsupported AEDAT version");
  celc::test::writeBytes(d.file("c.aedat4"), "#!AER-DAT4.0 \n");
  EXPECT_IO_ERROR(openEventSource(d.file("c.aedat4")), "byte 0", "bad magic");
  celc::test::writeBytes(d.file("d.aedat31"), "#!AER-DAT3.1x\r\n");
  EXPECT_IO_ERROR(openEventSource(d.file("d.aedat31")), "byte 0", "bad magic");
}

TEST(IoAedatBad, Aedat2TruncatedRecordAndHeader) {
  TempDir d;
  auto f = fixture(1000);
  writeAedat2(d.file("a.aedat"), f.ev, {});
  std::string b = celc::test::readBytes(d.file("a.aedat"));
  celc::test::writeBytes(d.file("t.aedat"), b.substr(0, b.size() - 3));
  {  // the complete records are read, the partial one is a warning naming where the file ends
    auto r = openEventSource(d.file("t.aedat"));
    EXPECT_EQ(readAllEvents(*r).size(), 999u);
    EXPECT_EQ(r->warnings().truncated, 1u);
  }
  ReaderOptions strict;
  strict.strict = true;
  EXPECT_IO_ERROR(celc::test::drain(d.file("t.aedat"), strict), "t.aedat: byte " + std::to_string(b.size() - 8),
                  "truncated event record", "file ends at byte " + std::to_string(b.size() - 3));
  // header cut inside the preferences block
  const std::size_t prefs = b.find("#End of Preferences");
  celc::test::writeBytes(d.file("h.aedat"), b.substr(0, prefs));
  EXPECT_IO_ERROR(openEventSource(d.file("h.aedat")), "byte " + std::to_string(prefs), "truncated");
  // header line cut without newline
  celc::test::writeBytes(d.file("l.aedat"), "#!AER-DAT2.0\r\n# AEChip: DAVIS240C");
  EXPECT_IO_ERROR(openEventSource(d.file("l.aedat")), "truncated");
  // unknown chip: the size is needed to flip y
  celc::test::writeBytes(d.file("u.aedat"), "#!AER-DAT2.0\r\n# AEChip: foo.Mystery\r\n");
  EXPECT_IO_ERROR(openEventSource(d.file("u.aedat")), "sensor size unknown", "Mystery");
  ReaderOptions o;
  o.width = 240, o.height = 180;
  EXPECT_NO_THROW(openEventSource(d.file("u.aedat"), o));
}

TEST(IoAedatBad, Aedat2OutsideSensorAndBackwards) {
  TempDir d;
  std::string b = "#!AER-DAT2.0\r\n# AEChip: x.DAVIS240C\r\n";
  auto pair = [&](std::uint32_t a, std::uint32_t t) {
    for (std::uint32_t v : {a, t})
      for (int s = 24; s >= 0; s -= 8) b.push_back(char((v >> s) & 0xFF));
  };
  pair((10u << 22) | (300u << 12), 100);  // x = 300 > 239
  pair((10u << 22) | (5u << 12), 200);
  pair((200u << 22) | (5u << 12), 300);   // y = 200 > 179
  pair((10u << 22) | (6u << 12), 150);    // backwards
  pair((10u << 22) | (7u << 12) | 0x400u, 400);  // external event: not a pixel
  celc::test::writeBytes(d.file("a.aedat"), b);
  auto r = openEventSource(d.file("a.aedat"));
  auto ev = readAllEvents(*r);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].y, 179.0f - 10.0f);  // flipped from the bottom-left origin
  EXPECT_EQ(r->warnings().outside_sensor, 2u);
  EXPECT_EQ(r->warnings().backwards_time, 1u);
  ReaderOptions strict;
  strict.strict = true;
  EXPECT_IO_ERROR(celc::test::drain(d.file("a.aedat"), strict), "byte ", "outside");
}

TEST(IoAedatBad, Aedat31HostileAndTruncatedPackets) {
  TempDir d;
  auto f = fixture(1000);
  writeAedat31(d.file("a.aedat31"), f.ev, {}, "DAVIS240C", 500);
  const std::string b = celc::test::readBytes(d.file("a.aedat31"));
  const std::size_t data = b.find("#!END-HEADER\r\n") + 14;
  // truncated inside the second packet: the first is read, a warning (an error with strict)
  ReaderOptions strict;
  strict.strict = true;
  celc::test::writeBytes(d.file("t.aedat31"), b.substr(0, b.size() - 100));
  {
    auto r = openEventSource(d.file("t.aedat31"));
    EXPECT_EQ(readAllEvents(*r).size(), 500u);
    EXPECT_EQ(r->warnings().truncated, 1u);
  }
  EXPECT_IO_ERROR(celc::test::drain(d.file("t.aedat31"), strict),
                  "byte " + std::to_string(data + 28 + 500 * 8), "beyond the end of the file");
  // hostile capacity: 2^31-1 events of 8 bytes (never allocated: beyond the file)
  std::string h = b;
  const std::int32_t huge = 0x7FFFFFFF;
  std::memcpy(&h[data + 16], &huge, 4);
  celc::test::writeBytes(d.file("h.aedat31"), h);
  EXPECT_IO_ERROR(celc::test::drain(d.file("h.aedat31"), strict), "byte " + std::to_string(data),
                  "beyond the end of the file");
  // capacity == number == large, but beyond the file
  std::string h2 = b;
  const std::int32_t big = 100000000;
  std::memcpy(&h2[data + 16], &big, 4);
  std::memcpy(&h2[data + 20], &big, 4);
  celc::test::writeBytes(d.file("h2.aedat31"), h2);
  EXPECT_IO_ERROR(celc::test::drain(d.file("h2.aedat31"), strict), "byte " + std::to_string(data), "beyond the end");
  // wrong event size for polarity
  std::string s = b;
  const std::int32_t nine = 9;
  std::memcpy(&s[data + 4], &nine, 4);
  celc::test::writeBytes(d.file("s.aedat31"), s);
  EXPECT_IO_ERROR(celc::test::drain(d.file("s.aedat31")), "byte " + std::to_string(data));
  // header without end
  celc::test::writeBytes(d.file("e.aedat31"), "#!AER-DAT3.1\r\n#Source 1: DAVIS240C\r\n");
  EXPECT_IO_ERROR(openEventSource(d.file("e.aedat31")), "END-HEADER");
  // pixel outside the sensor: x = 500
  std::string o = b;
  const std::uint32_t px = (500u << 17) | (3u << 2) | 1u;
  std::memcpy(&o[data + 28], &px, 4);
  celc::test::writeBytes(d.file("o.aedat31"), o);
  auto r = openEventSource(d.file("o.aedat31"));
  EXPECT_EQ(readAllEvents(*r).size(), 999u);
  EXPECT_EQ(r->warnings().outside_sensor, 1u);
}

TEST(IoAedatBad, Aedat4HostileSizesCorruptFramesAndBombs) {
  TempDir d;
  auto f = fixture(5000, 320, 240);
  writeAedat4(d.file("a.aedat4"), f.ev, f.imu, 320, 240, Aedat4Compression::Lz4, 1000, false);
  const std::string b = celc::test::readBytes(d.file("a.aedat4"));
  std::int32_t hsize;
  std::memcpy(&hsize, &b[14], 4);
  const std::size_t first = 18 + std::size_t(hsize);
  // hostile IOHeader size
  std::string h = b;
  const std::int32_t huge = 0x7FFFFFF0;
  std::memcpy(&h[14], &huge, 4);
  celc::test::writeBytes(d.file("h.aedat4"), h);
  EXPECT_IO_ERROR(openEventSource(d.file("h.aedat4")), "byte 14", "IOHeader size");
  // hostile packet size: beyond the file, so read as a cut (never allocated); an error with strict
  ReaderOptions strict;
  strict.strict = true;
  std::string p = b;
  std::memcpy(&p[first + 4], &huge, 4);
  celc::test::writeBytes(d.file("p.aedat4"), p);
  EXPECT_IO_ERROR(celc::test::drain(d.file("p.aedat4"), strict), "byte " + std::to_string(first), "packet of");
  const std::int32_t negative = -5;
  std::memcpy(&p[first + 4], &negative, 4);
  celc::test::writeBytes(d.file("n.aedat4"), p);
  EXPECT_IO_ERROR(celc::test::drain(d.file("n.aedat4")), "byte " + std::to_string(first), "packet size -5");
  // truncated file
  celc::test::writeBytes(d.file("t.aedat4"), b.substr(0, b.size() - 50));
  EXPECT_IO_ERROR(celc::test::drain(d.file("t.aedat4"), strict), "truncated");
  // corrupt LZ4 frame (garbage in the first packet's payload)
  std::string c = b;
  for (std::size_t i = first + 8 + 10; i < first + 8 + 60; ++i) c[i] = char(0xA5);
  celc::test::writeBytes(d.file("c.aedat4"), c);
  EXPECT_IO_ERROR(celc::test::drain(d.file("c.aedat4")), "byte " + std::to_string(first));
  // decompression bomb guard: a limit smaller than one decoded packet (1000 * 16 bytes)
  ReaderOptions small;
  small.max_packet_bytes = 12000;  // > the compressed packet (~9 kB), < decoded (16 kB)
  EXPECT_IO_ERROR(celc::test::drain(d.file("a.aedat4"), small), "beyond the 12000-byte limit");
}

TEST(IoAedatBad, Aedat4FlatbufferOffsetsChecked) {
  TempDir d;
  auto f = fixture(100, 320, 240);
  writeAedat4(d.file("a.aedat4"), f.ev, {}, 320, 240, Aedat4Compression::None, 1000, false);
  const std::string b = celc::test::readBytes(d.file("a.aedat4"));
  std::int32_t hsize;
  std::memcpy(&hsize, &b[14], 4);
  const std::size_t payload = 18 + std::size_t(hsize) + 8;
  // the EventPacket vector count (payload layout of the writer: count at 36)
  std::string v = b;
  const std::uint32_t many = 0x10000000;
  std::memcpy(&v[payload + 36], &many, 4);
  celc::test::writeBytes(d.file("v.aedat4"), v);
  const std::string at = "byte " + std::to_string(payload - 8);
  EXPECT_IO_ERROR(celc::test::drain(d.file("v.aedat4")), at, "'EVTS' flatbuffer", "fails verification");
  // the root offset pointing outside
  std::string r = b;
  const std::uint32_t far = 0x00FFFFFF;
  std::memcpy(&r[payload + 4], &far, 4);
  celc::test::writeBytes(d.file("r.aedat4"), r);
  EXPECT_IO_ERROR(celc::test::drain(d.file("r.aedat4")), at, "fails verification");
  // a wrong identifier
  std::string i = b;
  i[payload + 8] = 'X';
  celc::test::writeBytes(d.file("i.aedat4"), i);
  EXPECT_IO_ERROR(celc::test::drain(d.file("i.aedat4")), "identifier");
}

/// Random byte flips and truncations of small valid files: every outcome is
/// either a successful read or an IoError (no crash, hang, other exception or
/// huge allocation: max_packet_bytes bounds every buffer).
TEST(IoAedatBad, MutationFuzzNeverCrashes) {
  TempDir d;
  auto f = fixture(600, 240, 180);
  writeAedat2(d.file("a.aedat2"), f.ev, f.imu);
  writeAedat31(d.file("a.aedat31"), f.ev, f.imu, "DAVIS240C", 100);
  writeAedat4(d.file("l.aedat4"), f.ev, f.imu, 240, 180, Aedat4Compression::Lz4, 100, true);
  writeAedat4(d.file("z.aedat4"), f.ev, f.imu, 240, 180, Aedat4Compression::Zstd, 100, true);
  writeAedat4(d.file("n.aedat4"), f.ev, f.imu, 240, 180, Aedat4Compression::None, 100, true);
  writeEventsText(d.file("e.txt"), f.ev);
  std::mt19937 rng(2024);
  ReaderOptions o;
  o.max_packet_bytes = 1 << 20;
  int errors = 0, oks = 0;
  for (const char* name : {"a.aedat2", "a.aedat31", "l.aedat4", "z.aedat4", "n.aedat4", "e.txt"}) {
    const std::string good = celc::test::readBytes(d.file(name));
    for (int trial = 0; trial < 60; ++trial) {
      std::string m = good;
      if (trial % 4 == 3) {
        m.resize(std::uniform_int_distribution<std::size_t>(0, m.size() - 1)(rng));
      } else {
        const int flips = 1 + trial % 8;
        for (int k = 0; k < flips; ++k)
          m[std::uniform_int_distribution<std::size_t>(0, m.size() - 1)(rng)] = char(rng() & 0xFF);
      }
      const std::string p = d.file(std::string("m_") + name);
      celc::test::writeBytes(p, m);
      try {
        (void)scanFile(p, o);
        ++oks;
      } catch (const IoError& e) {
        ++errors;
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << " trial " << trial << ": unexpected exception " << e.what();
      }
    }
  }
  EXPECT_GT(errors, 50);  // the corruptions are mostly detected
  EXPECT_GT(oks, 10);     // flips inside event payloads stay readable
}

// ---- conformance with ../shared/data (README facts) --------------------------------

TEST(IoAedatConformance, Davis240Aedat2) {
  const std::string p = celc::test::sharedData("aedat/davis240c_translation_boxes.aedat2");
  SKIP_IF_NO_SHARED(p);
  auto r = openEventSource(p);
  EXPECT_EQ(r->width(), 240);
  EXPECT_EQ(r->height(), 180);
  auto ev = readAllEvents(*r);
  ASSERT_EQ(ev.size(), 162771u);
  std::size_t on = 0;
  for (const auto& e : ev) on += e.on;
  EXPECT_EQ(on, 82944u);
  EXPECT_EQ(std::llround(ev.front().t * 1e6), 294976755);
  EXPECT_EQ(std::llround(ev.back().t * 1e6), 297049406);
  auto imu = r->readImu();
  ASSERT_EQ(imu.size(), 4833u);
  // ~429 us apart
  EXPECT_NEAR((imu.back().t - imu.front().t) / double(imu.size() - 1), 429e-6, 5e-6);
  // at rest about (0.01, -1.0, -0.03) g with the header's 8 g scale
  const Vec3 a0 = imu.front().accel / kG;
  EXPECT_NEAR(a0.x(), 0.01, 0.1);
  EXPECT_NEAR(a0.y(), -1.0, 0.1);
  EXPECT_NEAR(a0.z(), -0.03, 0.1);
  EXPECT_EQ(r->warnings().total(), 0u);
}

TEST(IoAedatConformance, DerivedAedat31MatchesAedat2) {
  const std::string p2 = celc::test::sharedData("aedat/davis240c_translation_boxes.aedat2");
  const std::string p3 = celc::test::sharedData("aedat/davis240c_translation_boxes.DERIVED.aedat31");
  SKIP_IF_NO_SHARED(p3);
  auto r2 = openEventSource(p2);
  auto r3 = openEventSource(p3);
  EXPECT_EQ(r3->width(), 240);
  // same events, same top-left convention (y flipped in both)
  expectSameEvents(readAllEvents(*r3), readAllEvents(*r2));
  auto imu3 = r3->readImu();
  auto imu2 = r2->readImu();
  ASSERT_EQ(imu3.size(), 4833u);
  // the transcoder negated accel x (README / header); gyro and accel y, z agree
  for (std::size_t i = 0; i < imu3.size(); i += 97) {
    EXPECT_NEAR(imu3[i].t, imu2[i].t, 1e-9);
    EXPECT_LT((imu3[i].gyro - imu2[i].gyro).norm(), 1e-4);
    EXPECT_NEAR(imu3[i].accel.y(), imu2[i].accel.y(), 1e-3);
    EXPECT_NEAR(imu3[i].accel.x(), -imu2[i].accel.x(), 1e-3);
  }
}

TEST(IoAedatConformance, DvxplorerAedat4AllCompressions) {
  const std::string lz4 = celc::test::sharedData("aedat/dvxplorer_sample_lz4.aedat4");
  SKIP_IF_NO_SHARED(lz4);
  auto r = openEventSource(lz4);
  EXPECT_EQ(r->width(), 320);
  EXPECT_EQ(r->height(), 240);
  auto ev = readAllEvents(*r);
  ASSERT_EQ(ev.size(), 111954u);
  std::size_t on = 0;
  for (const auto& e : ev) on += e.on;
  EXPECT_EQ(on, 55023u);
  EXPECT_EQ(std::llround(ev.front().t * 1e6), 1605537493718345LL);
  EXPECT_EQ(std::llround(ev.back().t * 1e6), 1605537494308262LL);
  auto imu = r->readImu();
  ASSERT_EQ(imu.size(), 475u);
  EXPECT_EQ(std::llround(imu.front().t * 1e6), 1605537493718788LL);
  const Vec3 a = imu.front().accel / kG, g = imu.front().gyro / kDeg;
  EXPECT_LT((a - Vec3(0.126, -0.995, -0.393)).norm(), 2e-3);
  EXPECT_LT((g - Vec3(0.412, 0.076, -0.412)).norm(), 2e-3);
  for (const char* other : {"aedat/dvxplorer_sample_zstd.DERIVED.aedat4",
                            "aedat/dvxplorer_sample_uncompressed.DERIVED.aedat4"}) {
    auto r2 = openEventSource(celc::test::sharedData(other));
    expectSameEvents(readAllEvents(*r2), ev);
    expectSameImu(r2->readImu(), imu, 1e-12, 1e-12);
  }
  // the file data table allows a time-range read
  auto rs = openEventSource(lz4);
  const double ts = ev[80000].t;
  ASSERT_TRUE(rs->seekTime(ts));
  auto rest = readAllEvents(*rs);
  EXPECT_LT(rest.size(), 111954u - 60000u);
  std::size_t want = 0, got = 0;
  for (const auto& e : ev) want += e.t >= ts;
  for (const auto& e : rest) got += e.t >= ts;
  EXPECT_EQ(got, want);
}

TEST(IoAedatConformance, HeaderOnlyTruncatedIsReported) {
  const std::string p = celc::test::sharedData("aedat/header_only_truncated.aedat");
  SKIP_IF_NO_SHARED(p);
  EXPECT_IO_ERROR(openEventSource(p), "header_only_truncated.aedat: byte 599", "truncated");
}

/// Files larger than the readers' block buffers (text 4 MB, AEDAT 2.0 8 MB):
/// lines and records straddling a refill, IMU samples split across blocks.
TEST(IoAedat, LargeFilesCrossBufferBoundaries) {
  TempDir d;
  auto ev = celc::test::randomEvents(1200000, 240, 180, 21, 1.0);  // 9.6 MB of AEDAT 2.0, ~26 MB of text
  auto imu = celc::test::randomImu(ev.front().t, ev.back().t, 22);
  writeAedat2(d.file("big.aedat"), ev, imu);
  auto r = openEventSource(d.file("big.aedat"));
  expectSameEvents(readAllEvents(*r), ev);
  expectSameImu(r->readImu(), imu, 0.51 / 32.8 * kDeg, 0.51 / 4096 * kG);
  TextWriteOptions crlf;
  crlf.crlf = true;
  writeEventsText(d.file("big.txt"), ev, crlf);
  auto rt = openEventSource(d.file("big.txt"));
  const auto got = readAllEvents(*rt);
  ASSERT_EQ(got.size(), ev.size());
  for (std::size_t i = 0; i < ev.size(); ++i) {
    ASSERT_NEAR(got[i].t, ev[i].t, 1e-9) << i;
    ASSERT_EQ(got[i].x, ev[i].x) << i;
    ASSERT_EQ(got[i].y, ev[i].y) << i;
    ASSERT_EQ(got[i].on, ev[i].on) << i;
  }
}

// ---- malformed and hostile inputs (docs/robustness.md's table) -------------------

// ---- AEDAT 3.1: signed overflow in the packet header check ----------------------

TEST(IoRobustness, Aedat31TimestampOffsetInt32MaxIsAnErrorNotOverflow) {
  TempDir d;
  writeAedat31(d.file("a.aedat31"), celc::test::randomEvents(50, 240, 180, 1), {}, "DAVIS240C", 50);
  std::string b = readBytes(d.file("a.aedat31"));
  const std::size_t data = b.find("#!END-HEADER\r\n") + 14;
  putLE32(b, data + 8, 0x7FFFFFFF);  // eventTSOffset: tsoff + 4 overflowed int before
  writeBytes(d.file("o.aedat31"), b);
  EXPECT_IO_ERROR(celc::test::drain(d.file("o.aedat31")), "byte " + std::to_string(data), "invalid packet header");
  // The largest overflow counter fits in int64 but puts the times near 4.6e12 s,
  // where a double in seconds resolves about 1 ms: an error naming the packet.
  b = readBytes(d.file("a.aedat31"));
  putLE32(b, data + 12, 0x7FFFFFFF);
  writeBytes(d.file("v.aedat31"), b);
  EXPECT_IO_ERROR(celc::test::drain(d.file("v.aedat31")), "v.aedat31: byte " + std::to_string(data),
                  "eventTSOverflow 2147483647", "beyond 2^33 s");
  // Just below 2^33 s (overflow 3,999,999) every microsecond still has its own double.
  b = readBytes(d.file("a.aedat31"));
  putLE32(b, data + 12, 3999999);
  writeBytes(d.file("w.aedat31"), b);
  auto r = openEventSource(d.file("w.aedat31"));
  const auto ev = readAllEvents(*r);
  ASSERT_EQ(ev.size(), 50u);
  EXPECT_GT(ev.front().t, 8.589e9);
  EXPECT_LE(std::nextafter(ev.front().t, 1e300) - ev.front().t, 1e-6);
  putLE32(b, data + 12, 4000000);
  writeBytes(d.file("w.aedat31"), b);
  EXPECT_IO_ERROR(celc::test::drain(d.file("w.aedat31")), "eventTSOverflow 4000000");
}

TEST(IoRobustness, Aedat4HeaderHugeSensorRefusedBeforeAnyTable) {
  TempDir d;
  const auto ev = celc::test::randomEvents(100, 240, 180, 2);
  writeAedat4(d.file("a.aedat4"), ev, {}, 6000, 6000, Aedat4Compression::Lz4, 50, true);
  EXPECT_IO_ERROR(openEventSource(d.file("a.aedat4")), "a.aedat4: byte 14", "6000x6000", "4096");
  writeAedat4(d.file("b.aedat4"), ev, {}, 4096, 4096, Aedat4Compression::None, 50, true);
  EXPECT_NO_THROW(celc::test::drain(d.file("b.aedat4")));
}

// ---- AEDAT 2.0: one corrupt timestamp does not shift the rest ------------------

TEST(IoRobustness, Aedat2OneTimestampAllOnesIsAnOutlierNotAWrap) {
  TempDir d;
  const auto ev = celc::test::randomEvents(2000, 240, 180, 3, 1.0);
  writeAedat2(d.file("a.aedat"), ev, {});
  std::string b = readBytes(d.file("a.aedat"));
  const std::size_t data = b.size() - 8 * ev.size();
  const std::size_t k = 1000;
  putBE32(b, data + 8 * k + 4, 0xFFFFFFFFu);
  writeBytes(d.file("o.aedat"), b);
  auto r = openEventSource(d.file("o.aedat"));
  const auto got = readAllEvents(*r);
  ASSERT_EQ(got.size(), ev.size() - 1);  // the outlier dropped
  EXPECT_NEAR(got.back().t, ev.back().t, 1e-9);  // nothing shifted by 2^32 us
  EXPECT_EQ(r->warnings().time_jumps, 1u);
  ASSERT_FALSE(r->warnings().messages.empty());
  EXPECT_NE(r->warnings().messages[0].find("byte " + std::to_string(data + 8 * k)), std::string::npos)
      << r->warnings().messages[0];
  EXPECT_IO_ERROR(celc::test::drain(d.file("o.aedat"), strictOptions()), "byte " + std::to_string(data + 8 * k),
                  "outlier");
}

// ---- truncated binary files: the complete packets, a warning ---------------------

// The parameter: the file written, by format (and AEDAT 4.0 compression).
class IoRobustnessTruncated : public ::testing::TestWithParam<const char*> {};

TEST_P(IoRobustnessTruncated, TruncatedBinaryFilesYieldTheirCompletePackets) {
  TempDir d;
  const auto ev = celc::test::randomEvents(3000, 240, 180, 4, 2.0);
  const auto imu = celc::test::randomImu(ev.front().t, ev.back().t, 5);
  struct Case {
    std::string name;
    std::size_t min_events;
  };
  writeAedat2(d.file("a.aedat2"), ev, imu);
  writeAedat31(d.file("a.aedat31"), ev, imu, "DAVIS240C", 500);
  writeAedat4(d.file("n.aedat4"), ev, imu, 240, 180, Aedat4Compression::None, 500, true);
  writeAedat4(d.file("l.aedat4"), ev, imu, 240, 180, Aedat4Compression::Lz4, 500, true);
  writeAedat4(d.file("z.aedat4"), ev, imu, 240, 180, Aedat4Compression::Zstd, 500, false);
  {
    const char* name = GetParam();
    SCOPED_TRACE(name);
    const std::string b = readBytes(d.file(name));
    // cut at 60% of the file: inside an event packet (or the data table)
    const std::size_t cut = b.size() * 6 / 10 + 3;
    writeBytes(d.file(std::string("t_") + name), b.substr(0, cut));
    auto r = openEventSource(d.file(std::string("t_") + name));
    const auto got = readAllEvents(*r);
    EXPECT_GT(got.size(), 1000u);
    EXPECT_LT(got.size(), ev.size());
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_NEAR(got[i].t, ev[i].t, 1e-9);
    EXPECT_GE(r->warnings().truncated, 1u);  // with a data table past the cut: the table too
    ASSERT_FALSE(r->warnings().messages.empty());
    EXPECT_NE(r->warnings().messages.back().find("byte " + std::to_string(cut)), std::string::npos)
        << r->warnings().messages.back();
    EXPECT_IO_ERROR(celc::test::drain(d.file(std::string("t_") + name), strictOptions()), "truncated",
                    "byte " + std::to_string(cut));
  }
}
INSTANTIATE_TEST_SUITE_P(Formats, IoRobustnessTruncated,
                         ::testing::Values("a.aedat2", "a.aedat31", "n.aedat4", "l.aedat4", "z.aedat4"),
                         [](const ::testing::TestParamInfo<const char*>& i) {
                           const std::string f = i.param;
                           return f[0] == 'a' ? f.substr(2) : "aedat4_" + std::string(f[0] == 'n' ? "none" : f[0] == 'l' ? "lz4" : "zstd");
                         });

// ---- found by fuzz_aedat4_zstd: a Zstd frame asking for a huge window -------------

TEST(IoRobustness, Aedat4ZstdFrameWithAHugeWindowIsAnErrorNotAnAllocation) {
  // The first Zstd frame with a 2-byte content size (header 0x60) is given a
  // header without one and the window descriptor 0xA0 (2^30 bytes): zstd used
  // to allocate the window (the fuzzer's frame: 98 MB from a 1.4 KB file).
  TempDir d;
  auto ev = celc::test::randomEvents(600, 240, 180, 6, 3.0);
  writeAedat4(d.file("z.aedat4"), ev, {}, 240, 180, Aedat4Compression::Zstd, 200, false);
  EXPECT_EQ(celc::test::drain(d.file("z.aedat4")), 600u);
  ASSERT_TRUE(patchBytes(d.file("z.aedat4"), "\x28\xb5\x2f\xfd\x60", 4, std::string("\x00\xA0", 2), Place::First));
  EXPECT_IO_ERROR(celc::test::drain(d.file("z.aedat4")), "z.aedat4: byte ",
                  "corrupt Zstd frame: Frame requires too much memory for decoding");
}

// ---- AEDAT 4.0: a size of any number of digits is bounded ------------------------

TEST(IoRobustness, Aedat4SevenDigitSensorSizeIsRefusedLikeAnyHugeSize) {
  TempDir d;
  const auto ev = celc::test::randomEvents(100, 240, 180, 2);
  writeAedat4(d.file("a.aedat4"), ev, {}, 1234567, 180, Aedat4Compression::None, 50, true);
  EXPECT_IO_ERROR(openEventSource(d.file("a.aedat4")), "a.aedat4: byte 14: stream 0 declares a 1234567x180 sensor (at most 4096x4096)");
  writeAedat4(d.file("b.aedat4"), ev, {}, 30000, 180, Aedat4Compression::None, 50, true);
  EXPECT_IO_ERROR(openEventSource(d.file("b.aedat4")), "b.aedat4: byte 14: stream 0 declares a 30000x180 sensor (at most 4096x4096)");
  // the digits are the value: leading zeros do not make a size unknown
  std::string b = readBytes(d.file("b.aedat4"));
  const std::size_t at = b.find(">30000<");
  ASSERT_NE(at, std::string::npos);
  b.replace(at + 1, 5, "00240");
  writeBytes(d.file("c.aedat4"), b);
  EXPECT_EQ(openEventSource(d.file("c.aedat4"))->width(), 240);
}
