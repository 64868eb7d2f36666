// Regression tests for malformed inputs and the readers' consistency checks:
// every reproducer is generated here, through the project's
// writers and byte edits. docs/robustness.md lists them with the behaviour each
// one checks.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>

#include "celc/core/yaml.hpp"
#include "celc/geometry/undistort.hpp"
#include "celc/io/calibration.hpp"
#include "celc/io/window_source.hpp"
#include "celc/io/writers.hpp"
#include "celc/pipeline/batch.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/render_sequence.hpp"
#include "bag_writer.hpp"
#include "h5_writer.hpp"
#include "io/ros_messages.hpp"
#include "io_test_util.hpp"

using namespace celc;
using celc::test::readBytes;
using celc::test::TempDir;
using celc::test::writeBytes;

namespace {

/// Printable ASCII on one line: what every message may contain.
void expectPrintable(const std::string& m) {
  for (char c : m) {
    const auto u = static_cast<unsigned char>(c);
    ASSERT_TRUE(u >= 0x20 && u < 0x7F) << "byte " << int(u) << " in message: " << m;
  }
}

std::string ioError(const std::function<void()>& f) {
  try {
    f();
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no IoError";
  return {};
}

void putLE32(std::string& b, std::size_t at, std::int32_t v) { std::memcpy(&b[at], &v, 4); }
void putBE32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b[at + std::size_t(k)] = char((v >> (24 - 8 * k)) & 0xFF);
}

/// `n` values first, first + step, ... of type T.
template <class T>
std::vector<T> range(std::size_t n, T first = T(0), T step = T(1)) {
  std::vector<T> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = T(first + T(i) * step);
  return v;
}
/// MVSEC events, n x 4 doubles: x = y = 0, t = t0 + i dt, polarity 1.
std::vector<double> mvsecEvents(std::size_t n, double t0, double dt) {
  std::vector<double> ev(n * 4, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    ev[4 * i + 2] = t0 + double(i) * dt;
    ev[4 * i + 3] = 1.0;
  }
  return ev;
}

/// Which place of a pattern patchBytes() edits.
enum class Place { Only, First, LastOfSeveral };
/// Overwrites the file at `path` with `bytes` from `offset` after the start of
/// `pattern` (at its only, first, or last of at least two places); false when
/// the pattern does not stand there that way.
bool patchBytes(const std::string& path, const std::string& pattern, std::size_t offset, const std::string& bytes,
                Place place = Place::Only) {
  std::string b = readBytes(path);
  const std::size_t first = b.find(pattern), last = b.rfind(pattern);
  if (first == std::string::npos || (place == Place::Only && first != last) ||
      (place == Place::LastOfSeveral && first == last))
    return false;
  b.replace((place == Place::LastOfSeveral ? last : first) + offset, bytes.size(), bytes);
  writeBytes(path, b);
  return true;
}

ReaderOptions strictOptions() {
  ReaderOptions o;
  o.strict = true;
  return o;
}

}  // namespace

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

// ---- sizes from headers bounded before allocation -------------------------------

TEST(IoRobustness, CalibrationYamlHugeSensorRefusedWithFileAndKey) {
  TempDir d;
  for (const char* size : {"65535", "4097"}) {
    writeBytes(d.file("c.yaml"), std::string("camera:\n  width: ") + size + "\n  height: 180\n  fx: 200\n  fy: 200\n"
                                 "  cx: 120\n  cy: 90\n");
    try {
      (void)loadCalibration(d.file("c.yaml"));
      ADD_FAILURE() << "accepted width " << size;
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("c.yaml"), std::string::npos) << m;
      EXPECT_NE(m.find("width"), std::string::npos) << m;
      EXPECT_NE(m.find("4096"), std::string::npos) << m;
    }
  }
}

TEST(IoRobustness, Aedat4HeaderHugeSensorRefusedBeforeAnyTable) {
  TempDir d;
  const auto ev = celc::test::randomEvents(100, 240, 180, 2);
  writeAedat4(d.file("a.aedat4"), ev, {}, 6000, 6000, Aedat4Compression::Lz4, 50, true);
  EXPECT_IO_ERROR(openEventSource(d.file("a.aedat4")), "a.aedat4: byte 14", "6000x6000", "4096");
  writeAedat4(d.file("b.aedat4"), ev, {}, 4096, 4096, Aedat4Compression::None, 50, true);
  EXPECT_NO_THROW(celc::test::drain(d.file("b.aedat4")));
}

TEST(IoRobustness, UndistortTableRefusesHugeSensorsAndReaderOptionsAreBounded) {
  CameraModel c;
  c.width = 30000;
  c.height = 30000;
  c.fx = c.fy = 300;
  c.cx = c.cy = 100;
  try {
    UndistortLut lut(c);
    ADD_FAILURE() << "built a 30000x30000 table";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds 4096x4096"), std::string::npos) << e.what();
  }
  ReaderOptions o;
  o.width = 5000;
  o.height = 10;
  EXPECT_NE(o.validate().find("4096"), std::string::npos);
}

// ---- AEDAT 2.0: one corrupt timestamp no longer shifts the rest ------------------

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

// ---- endless windowing across an outlier ----------------------------------------

TEST(IoRobustness, OutlierTimestampInTextDoesNotMakeEndlessWindows) {
  TempDir d;
  for (const char* outlier : {"10000000", "1e300"}) {
    std::string text;
    for (int i = 0; i < 2000; ++i) {
      char line[64];
      std::snprintf(line, sizeof line, "%.6f %d %d 1\n", 1.0 + i * 1e-3, i % 240, i % 180);
      text += line;
      if (i == 700) text += std::string(outlier) + " 5 5 1\n";
    }
    writeBytes(d.file("e.txt"), text);
    auto r = openEventSource(d.file("e.txt"));
    WindowOptions w;
    w.seconds_per_window = 0.1;
    WindowSource src(*r, w);
    EventWindow win;
    std::size_t n = 0;
    const auto start = std::chrono::steady_clock::now();
    while (src.next(win) && n < 1000) ++n;
    EXPECT_LT(n, 25u) << outlier;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    EXPECT_EQ(r->warnings().time_jumps, 1u) << outlier;
    EXPECT_NE(r->warnings().messages.at(0).find("line 702"), std::string::npos) << r->warnings().messages.at(0);
  }
}

TEST(IoRobustness, WindowSourceSkipsLongGapsAndRefusesUnrepresentableTimes) {
  TempDir d;
  // a real gap (two events confirm it): kept by the reader, skipped by the windows
  writeBytes(d.file("g.txt"), "1.0 1 1 1\n1.05 1 1 1\n1.25 1 1 1\n5000.0 2 2 1\n5000.01 2 2 1\n5000.2 2 2 1\n");
  auto r = openEventSource(d.file("g.txt"));
  WindowOptions w;
  w.seconds_per_window = 0.1;
  WindowSource src(*r, w);
  EventWindow win;
  std::vector<EventWindow> got;
  while (src.next(win) && got.size() < 100) got.push_back(win);
  // 1.0-1.3 s: three windows, then the window holding 5000.0 (the grid's rounding
  // near 5000 s may put it one window earlier) and the one holding 5000.01
  ASSERT_GE(got.size(), 4u);
  ASSERT_LE(got.size(), 5u);
  EXPECT_EQ(got[1].events.size(), 0u);  // a gap of one window is returned empty, as before
  EXPECT_EQ(got[2].events.size(), 1u);
  EXPECT_GT(got[3].t0, 4999.8);
  EXPECT_LE(got[3].t0, 5000.0);
  EXPECT_GT(got.back().t1, 5000.01);
  EXPECT_EQ(src.gaps(), 1u);
  EXPECT_GT(src.skippedWindows(), 40000u);
  ASSERT_EQ(src.reports().size(), 1u);
  EXPECT_NE(src.reports()[0].find("g.txt: no events in"), std::string::npos) << src.reports()[0];
  EXPECT_EQ(r->warnings().time_jumps, 1u);  // the reader reports the gap too
  // a gap to 1e300: the window grid restarts there and t0 + S == t0 is an error, not a loop
  writeBytes(d.file("h.txt"), "1.0 1 1 1\n1.2 1 1 1\n1e300 2 2 1\n1e300 2 2 1\n");
  auto r2 = openEventSource(d.file("h.txt"));
  WindowSource src2(*r2, w);
  std::size_t n = 0;
  EXPECT_IO_ERROR(
      while (src2.next(win) && n < 100) ++n, "h.txt", "too large for windows");
  EXPECT_LT(n, 100u);
}

// ---- messages never echo raw bytes ---------------------------------------------

TEST(IoRobustness, MessagesArePrintableOneLine) {
  TempDir d;
  std::vector<std::string> messages;
  // control bytes and an ANSI escape in a field
  writeBytes(d.file("c.txt"), std::string("0.1\x01\x1b[31m 1 2 1\n"));
  messages.push_back(ioError([&] { celc::test::drain(d.file("c.txt")); }));
  // invalid UTF-8 in a header line (after a valid first block, so detection passes)
  writeBytes(d.file("u.txt"), std::string("0.1 1 2 1\ntime col\xff\xfe row sign\n"));
  messages.push_back(ioError([&] { celc::test::drain(d.file("u.txt")); }));
  // a field with a carriage return inside the line
  writeBytes(d.file("r.txt"), std::string("0.1 1 2 1\n0.2 1\r2 1 1\n"));
  messages.push_back(ioError([&] { celc::test::drain(d.file("r.txt")); }));
  // an AEDAT version "line" that spans two lines and holds control bytes
  writeBytes(d.file("v.aedat"), std::string("#!AER-DAT9.9\rsecond line\n\x07\x1b[2J"));
  messages.push_back(ioError([&] { openEventSource(d.file("v.aedat")); }));
  // AEDAT 2.0 / 3.1 magic lines with junk
  writeBytes(d.file("m2.aedat"), std::string("#!AER-DAT2.0\x1b[0m\xff\r\n"));
  messages.push_back(ioError([&] { openEventSource(d.file("m2.aedat")); }));
  writeBytes(d.file("m3.aedat"), std::string("#!AER-DAT3.1\x01\x02\xc3\x28\r\n"));
  messages.push_back(ioError([&] { openEventSource(d.file("m3.aedat")); }));
  // an AEDAT 2.0 chip name with control bytes: the note and the error are printable
  writeBytes(d.file("chip.aedat"), std::string("#!AER-DAT2.0\r\n# AEChip: x.\x1b]0;DVS128\x07\r\n"));
  messages.push_back(ioError([&] { openEventSource(d.file("chip.aedat")); }));
  for (const auto& m : messages) {
    SCOPED_TRACE(m);
    EXPECT_FALSE(m.empty());
    expectPrintable(m);
    EXPECT_LT(m.size(), 600u);
  }
  EXPECT_EQ(messages[3].find("second line"), std::string::npos);  // the version ends at the line's end
  EXPECT_EQ(detail::printable("a\nb\xff", 80), "a\\x0Ab\\xFF");
  EXPECT_EQ(detail::printable(std::string(100, 'x'), 10), "xxxxxxxxxx...");
}

TEST(IoRobustness, RandomBinaryIsDetectedByItsHeaderAndNeverPrinted) {
  TempDir d;
  std::mt19937 rng(15);
  // no NUL in the first 16 bytes (the old detector's window), NULs and control bytes later
  std::string b;
  for (int i = 0; i < 4096; ++i) b.push_back(char(i < 16 ? 'a' + rng() % 26 : rng() & 0xFF));
  writeBytes(d.file("r.bin"), b);
  std::string m = ioError([&] { openEventSource(d.file("r.bin")); });
  expectPrintable(m);
  EXPECT_NE(m.find("binary data"), std::string::npos) << m;
  EXPECT_LT(m.size(), 200u) << m;
  // bytes >= 0x80 only (no control byte at all): invalid UTF-8 is binary too
  std::string h;
  for (int i = 0; i < 4096; ++i) h.push_back(char(0x80 | (rng() & 0x7F)));
  writeBytes(d.file("h.bin"), "0.1 1 2 1\n" + h);
  m = ioError([&] { openEventSource(d.file("h.bin")); });
  EXPECT_NE(m.find("binary data"), std::string::npos) << m;
  expectPrintable(m);
  // UTF-8 text in a comment is still text
  writeBytes(d.file("t.txt"), "# t [\xc2\xb5s] x y p\n0.1 1 2 1\n");
  EXPECT_EQ(detectFormat(d.file("t.txt")), Format::Text);
}

// ---- truncated binary files: the complete packets, a warning ---------------------

TEST(IoRobustness, TruncatedBinaryFilesYieldTheirCompletePackets) {
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
  for (const char* name : {"a.aedat2", "a.aedat31", "n.aedat4", "l.aedat4", "z.aedat4"}) {
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

// ---- time sanity ---------------------------------------------------------------

TEST(IoRobustness, BackwardsBeyondToleranceIsAnErrorOrDroppedOrSorted) {
  TempDir d;
  writeBytes(d.file("e.txt"), "0.1 1 2 1\n0.3 1 2 1\n0.2995 1 2 1\n0.2 1 2 1\n0.4 1 2 1\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("e.txt")), "e.txt: line 4", "backwards_tolerance", "input.backwards");
  ReaderOptions drop;
  drop.backwards = BackwardsPolicy::Drop;
  auto r = openEventSource(d.file("e.txt"), drop);
  EXPECT_EQ(readAllEvents(*r).size(), 4u);
  EXPECT_EQ(r->warnings().backwards_time, 2u);  // 0.2995 kept (within 1 ms), 0.2 dropped
  ReaderOptions sort;
  sort.backwards = BackwardsPolicy::Sort;
  auto s = openEventSource(d.file("e.txt"), sort);
  const auto ev = readAllEvents(*s);
  ASSERT_EQ(ev.size(), 5u);
  for (std::size_t i = 1; i < ev.size(); ++i) EXPECT_LE(ev[i - 1].t, ev[i].t);
  EXPECT_EQ(s->warnings().backwards_time, 2u);
}

TEST(IoRobustness, ForwardJumpOutlierDroppedGapKeptBothReported) {
  TempDir d;
  writeBytes(d.file("o.txt"), "1.0 1 2 1\n1.1 1 2 1\n99.0 1 2 1\n1.2 1 2 1\n1.3 1 2 1\n");
  auto r = openEventSource(d.file("o.txt"));
  auto ev = readAllEvents(*r);
  ASSERT_EQ(ev.size(), 4u);
  EXPECT_DOUBLE_EQ(ev[2].t, 1.2);
  ASSERT_EQ(r->warnings().time_jumps, 1u);
  EXPECT_NE(r->warnings().messages[0].find("line 3"), std::string::npos) << r->warnings().messages[0];
  EXPECT_NE(r->warnings().messages[0].find("outlier dropped"), std::string::npos);
  ReaderOptions tight;
  tight.max_time_jump = 100.0;  // the bound is the schema option input.max_time_jump
  auto r2 = openEventSource(d.file("o.txt"), tight);
  EXPECT_IO_ERROR(readAllEvents(*r2), "line 4", "before the latest event so far");
  writeBytes(d.file("g.txt"), "1.0 1 2 1\n1.1 1 2 1\n99.0 1 2 1\n99.1 1 2 1\n");
  auto r3 = openEventSource(d.file("g.txt"));
  EXPECT_EQ(readAllEvents(*r3).size(), 4u);
  EXPECT_EQ(r3->warnings().time_jumps, 1u);
  EXPECT_NE(r3->warnings().messages[0].find("a gap of"), std::string::npos) << r3->warnings().messages[0];
}

TEST(IoRobustness, ManyPixelsOutsideTheSensorAreAnError) {
  TempDir d;
  std::string text;
  for (int i = 0; i < 1000; ++i) text += std::to_string(0.001 * i + 1.0) + " " + std::to_string(i % 346) + " 10 1\n";
  writeBytes(d.file("e.txt"), text);
  ReaderOptions o;
  o.width = 240;
  o.height = 180;
  EXPECT_IO_ERROR(celc::test::drain(d.file("e.txt"), o), "e.txt: line", "outside the 240x180 sensor",
                  "max_outside_share");
  o.max_outside_share = 1.0;
  auto r = openEventSource(d.file("e.txt"), o);
  EXPECT_EQ(readAllEvents(*r).size(), 240u * 3);
}

TEST(IoRobustness, MicrosecondsReadAsSecondsGiveAHint) {
  TempDir d;
  std::string text;
  for (int i = 0; i < 200; ++i) text += std::to_string(1600000000 + 7 * i) + " 1 2 1\n";
  writeBytes(d.file("us.txt"), text);
  EXPECT_IO_ERROR(celc::test::drain(d.file("us.txt")), "us.txt: line 64", "input.time_scale", "--time-scale 1e-6");
  ReaderOptions o;
  o.text_time_scale = 1e-6;
  EXPECT_EQ(celc::test::drain(d.file("us.txt"), o), 200u);
}

TEST(IoRobustness, ReaderOptionsSchemaHasTheTimeChecks) {
  ReaderOptions o;
  const auto yaml = writeYaml([&](FieldVisitor& v) { describe(v, o); });
  for (const char* key : {"max_time_jump", "backwards_tolerance", "backwards", "max_outside_share"})
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
}

// ---- YAML: a key or section given twice names both lines ------------------------

TEST(IoRobustness, DuplicatedSectionsInCalibrationSceneAndBatchNameBothLines) {
  TempDir d;
  auto configError = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const ConfigError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no ConfigError";
    return {};
  };
  writeBytes(d.file("c.yaml"), "camera:\n  width: 240\n  height: 180\n  fx: 200\n  fy: 200\n  cx: 120\n  cy: 90\n"
                               "imu:\n  time_offset: 0.1\nimu:\n  time_offset: 0.2\n");
  std::string m = configError([&] { (void)loadCalibration(d.file("c.yaml")); });
  EXPECT_NE(m.find("c.yaml:10"), std::string::npos) << m;
  EXPECT_NE(m.find("given twice (first at line 8)"), std::string::npos) << m;
  const std::string scene = readBytes(std::string(CELC_SOURCE_DIR) + "/config/scenes/davis240_rectangles.yaml");
  writeBytes(d.file("s.yaml"), scene + "duration: 2.0\n");
  m = configError([&] { (void)loadSynthConfig(d.file("s.yaml")); });
  EXPECT_NE(m.find("s.yaml:"), std::string::npos) << m;
  EXPECT_NE(m.find("'duration': given twice (first at line 7)"), std::string::npos) << m;
  writeBytes(d.file("b.yaml"), "sequences:\n  - label: a\n    path: x\n    path: y\n");
  m = configError([&] { (void)readBatch(d.file("b.yaml"), [](const std::string&) { return RunConfig{}; }); });
  EXPECT_NE(m.find("b.yaml:4"), std::string::npos) << m;
  EXPECT_NE(m.find("given twice (first at line 3)"), std::string::npos) << m;
}

// ---- found by fuzz_calibration: a YAML syntax error quoting a raw byte ------------

TEST(IoRobustness, CalibrationYamlSyntaxErrorIsPrintable) {
  TempDir d;
  writeBytes(d.file("c.yaml"), std::string("camera: \"\\\xcd\xdf\"\n"));  // an unknown escape: a byte >= 0x80
  try {
    (void)loadCalibration(d.file("c.yaml"));
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    expectPrintable(m);
    EXPECT_NE(m.find("c.yaml:1"), std::string::npos) << m;
  }
}

// ---- found by fuzz_hdf5: a chunk layout that disagrees with its stored chunks -------

TEST(IoRobustness, Hdf5ChunkLayoutLargerThanItsStoredChunksIsAnError) {
  // An MVSEC file whose events are stored in unfiltered chunks of 16 x 4 doubles
  // (512 bytes each), written by libhdf5; then the layout message's chunk rows
  // 16 -> 199 (the fuzzer's change): the HDF5 library used to copy 6368 bytes
  // out of each 512-byte chunk buffer (a heap overflow inside libhdf5).
  TempDir d;
  const std::string h5 = d.file("m.h5");
  {
    celc::test::h5::File f(h5);
    celc::test::h5::DatasetOptions chunked;
    chunked.chunks = {16, 4};
    f.write("davis/left/events", mvsecEvents(60, 1.0, 1e-5), {60, 4}, chunked);
  }
  EXPECT_EQ(celc::test::drain(h5), 60u);  // the file as written reads
  // the layout message's dimensions: chunk rows, columns, then the element size (uint32 each)
  ASSERT_TRUE(patchBytes(h5, std::string("\x10\x00\x00\x00\x04\x00\x00\x00\x08\x00\x00\x00", 12), 0, "\xC7"));
  EXPECT_IO_ERROR(celc::test::drain(h5), "m.h5: dataset /davis/left/events: chunk 0 at byte",
                  "holds 512 bytes, an unfiltered chunk of its layout 6368 (damaged file)");
}

TEST(IoRobustness, Hdf5CompactDataShorterThanItsDatasetIsAnError) {
  // A DSEC file whose /events/x is stored compact (in its object header, 60
  // uint16 = 120 bytes), written by libhdf5; then the layout message's compact size
  // 120 -> 0 (the fuzzer turned a chunked layout into a compact one of no
  // bytes): the HDF5 library used to copy the values from a null buffer.
  TempDir d;
  const std::string h5 = d.file("c.h5");
  {
    const std::size_t n = 60;
    celc::test::h5::File f(h5);
    celc::test::h5::DatasetOptions compact;
    compact.compact = true;
    f.write("events/x", range<std::uint16_t>(n, 0x4100), {}, compact);
    f.write("events/y", std::vector<std::uint16_t>(n, 0));
    f.write("events/t", range<std::uint32_t>(n));
    f.write("events/p", std::vector<std::uint8_t>(n, 1));
  }
  EXPECT_EQ(celc::test::drain(h5), 60u);  // the file as written reads
  // the compact layout message: version 3, class 0, size 120 (uint16), then x = 0x4100, 0x4101, ...
  ASSERT_TRUE(patchBytes(h5, std::string("\x03\x00\x78\x00\x00\x41\x01\x41", 8), 2, std::string(1, '\0')));
  EXPECT_IO_ERROR(celc::test::drain(h5), "c.h5: dataset /events/x: compact data of 0 bytes for 120 bytes of values",
                  "(damaged file)");
}

TEST(IoRobustness, Hdf5CompressedChunkLargerThanTheFileIsAnError) {
  // A DSEC file whose /events/x is stored in gzip chunks of 32 values, written
  // by libhdf5; then the chunk index's stored size of chunk 0 (a uint32 followed
  // by the filter mask and the chunk's offsets, all 0) -> 0x745F0000 (found by
  // the CI fuzz run): the HDF5 library allocated 1.9 GB to read it.
  TempDir d;
  const std::string h5 = d.file("z.h5");
  unsigned long long size = 0;
  {
    const std::size_t n = 60;
    celc::test::h5::File f(h5);
    celc::test::h5::DatasetOptions gzip;
    gzip.chunks = {32};
    gzip.gzip = 4;
    f.write("events/x", range<std::uint16_t>(n), {}, gzip);
    f.write("events/y", std::vector<std::uint16_t>(n, 0));
    f.write("events/t", range<std::uint32_t>(n));
    f.write("events/p", std::vector<std::uint8_t>(n, 1));
    size = f.chunkStoredSize("events/x", 0);
  }
  // the chunk index entry: stored size, filter mask 0, offsets 0 (two uint64)
  std::string key(24, '\0');
  const auto size32 = std::uint32_t(size);
  std::memcpy(&key[0], &size32, 4);
  ASSERT_TRUE(patchBytes(h5, key, 0, "\x00\x00\x5F\x74"));
  EXPECT_IO_ERROR(celc::test::drain(h5), "z.h5: dataset /events/x: compressed chunk 0 at byte",
                  "claims 1952382976 bytes, more than the file's");
}

// ---- found by fuzz_rosbag: a connection header whose field length runs past its data ---

TEST(IoRobustness, BagConnectionHeaderFieldBeyondItsDataIsAnError) {
  // A bag with one std_msgs/String message (the test tree's bag writer); then, in the index
  // section, the length of the connection header's `topic=/t` field 8 ->
  // 0x7FFFFFF0: the bag library copied that many bytes out of its buffer while
  // opening the bag (a heap overflow inside librosbag-storage).
  TempDir d;
  const std::string bag = d.file("c.bag");
  {
    namespace rb = celc::test::bag;
    rb::Writer b(bag, rb::Compression::None);
    b.write("/t", rb::messageType("std_msgs/String"), rb::string("hello"), rb::Time{1, 0});
  }
  EXPECT_IO_ERROR(celc::test::drain(bag), "no dvs_msgs/EventArray topic");  // the file as written opens
  // the index section's copy of the field (the chunk holds the other)
  ASSERT_TRUE(patchBytes(bag, std::string("\x08\x00\x00\x00topic=/t", 12), 0, "\xF0\xFF\xFF\x7F", Place::LastOfSeveral));
  EXPECT_IO_ERROR(celc::test::drain(bag), "c.bag: byte ",
                  "connection record data: field of 2147483632 bytes beyond its end");
}

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

TEST(IoRobustness, Bag12RecordHeaderLongerThanTheFileIsAnError) {
  // Found by the rosbag campaign: a format 1.2 bag (no index checks then) whose
  // first record declares a 1.4 GB header; the bag library allocated it.
  TempDir d;
  std::string b = "#ROSBAG V1.2\n";
  b += std::string("\x00\x00\x50\x53", 4) + "op=\x03" + std::string(40, '\0');
  writeBytes(d.file("o.bag"), b);
  EXPECT_IO_ERROR(celc::test::drain(d.file("o.bag")), "o.bag: byte 13: record: record header length 1397751808",
                  "beyond the end of the file");
}

// ---- a bag's index against its messages ------------------------------------------

TEST(IoRobustness, BagIndexConnectionMustBeItsMessagesConnection) {
  // A bag of two std_msgs/String topics in several chunks (the test tree's bag writer),
  // then three copies: the connection id of the first index data record after
  // the second chunk swapped for the other topic's (the library decoded those
  // messages as the other topic's type) or for an id no connection declares
  // (the messages vanished), and a chunk info's count made 0x7FFFFFFF (the
  // library's "wanted 4 bytes").
  TempDir d;
  const std::string bag = d.file("c.bag");
  namespace rb = celc::test::bag;
  {
    rb::Writer b(bag, rb::Compression::None, 300);
    const auto& type = rb::messageType("std_msgs/String");
    for (std::uint32_t i = 0; i < 12; ++i) {
      b.write("/a", type, rb::string(std::string(64, 'x')), rb::Time{1 + i, 0});
      b.write("/b", type, rb::string(std::string(64, 'x')), rb::Time{1 + i, 5});
    }
  }
  const std::string data = readBytes(bag);
  const auto recs = rb::records(data);
  std::vector<std::size_t> chunks;
  for (std::size_t i = 0; i < recs.size(); ++i)
    if (recs[i].op == 5) chunks.push_back(i);
  ASSERT_GE(chunks.size(), 3u);
  const rb::Record& ix = recs[chunks[1] + 1];
  ASSERT_EQ(ix.op, 4);
  const std::uint64_t conn = rb::readU32(data, ix.at("conn"));
  for (const auto& [ext, value] : {std::pair<const char*, std::uint32_t>{".mis", std::uint32_t(1 - conn)}, {".unk", 7u}}) {
    std::string c = data;
    rb::writeU32(c, ix.at("conn"), value);
    writeBytes(bag + ext, c);
  }
  const rb::Record* info = nullptr;
  for (const auto& r : recs)
    if (r.op == 6 && !info) info = &r;
  ASSERT_NE(info, nullptr);
  {
    std::string c = data;
    rb::writeU32(c, info->at("count"), 0x7FFFFFFF);
    writeBytes(bag + ".ci", c);
  }
  {  // the first message data record of the first chunk: after the /a connection record that opens it
    const rb::Record& chunk = recs[chunks[0]];
    const std::size_t first_data = chunk.data_at + 4 + rb::readU32(data, chunk.data_at) + 4;
    std::string c = data;
    rb::writeU32(c, data.find("conn=", first_data) + 5, 7);
    writeBytes(bag + ".msg", c);
  }
  const std::uint64_t index_at = ix.start, info_at = info->start, chunk_at = recs[chunks[0]].start;
  EXPECT_IO_ERROR(celc::test::drain(bag), "no dvs_msgs/EventArray topic");  // the file as written opens
  const std::string other = std::to_string(1 - conn);
  // the first entry of the index data record: its data follows the header
  EXPECT_IO_ERROR(celc::test::drain(bag + ".mis"), "c.bag.mis: byte ",
                  "index data record of connection " + other + " points at a message record of connection " +
                      std::to_string(conn));
  EXPECT_IO_ERROR(celc::test::drain(bag + ".unk"), "c.bag.unk: byte " + std::to_string(index_at),
                  "index data record of connection 7, which no connection record of the index declares");
  EXPECT_IO_ERROR(celc::test::drain(bag + ".ci"), "c.bag.ci: byte " + std::to_string(info_at),
                  "chunk info record of 2147483647 connection counts (8 bytes each) in 16 bytes of data");
  // a message record inside the first chunk naming connection 7
  EXPECT_IO_ERROR(celc::test::drain(bag + ".msg"), "c.bag.msg: byte " + std::to_string(chunk_at) + ": chunk record at offset ",
                  "message data record of connection 7, which no connection record of the index declares");
  for (const char* ext : {".mis", ".unk", ".ci", ".msg"}) {
    try {
      celc::test::drain(bag + ext);
    } catch (const IoError& e) {
      expectPrintable(e.what());
    }
  }
}

TEST(IoRobustness, BagImuValuesBeyondAnyImuAreAnErrorNotARate) {
  // sensor_msgs/Imu: header (seq, stamp, empty frame_id: 16 bytes), orientation
  // and its covariance (104), angular_velocity at byte 120, its covariance,
  // linear_acceleration at byte 216, its covariance: 312 bytes.
  std::vector<unsigned char> m(312, 0);
  auto put = [&](std::size_t at, double v) { std::memcpy(&m[at], &v, 8); };
  put(120, 0.5);
  put(216 + 16, 9.81);
  const ImuSample s = detail::decodeImu(m.data(), m.size());
  EXPECT_EQ(s.gyro.x(), 0.5);
  EXPECT_EQ(s.accel.z(), 9.81);
  auto offsetOf = [&]() -> std::size_t {
    try {
      detail::decodeImu(m.data(), m.size());
    } catch (const detail::RosDecodeError& e) {
      EXPECT_NE(std::string(e.what()).find("not an IMU sample"), std::string::npos) << e.what();
      return e.offset;
    }
    ADD_FAILURE() << "no error";
    return 0;
  };
  put(120, -1.4e302);  // what an EventArray read as an Imu gave
  EXPECT_EQ(offsetOf(), 120u);
  put(120, 1001.0);  // beyond kMaxImuGyro
  EXPECT_EQ(offsetOf(), 120u);
  put(120, 999.0);
  EXPECT_NO_THROW(detail::decodeImu(m.data(), m.size()));
  put(216, std::nan(""));
  EXPECT_EQ(offsetOf(), 216u);
  put(216, 2e4);  // beyond kMaxImuAccel
  EXPECT_EQ(offsetOf(), 216u);
}

// ---- a corrupt first timestamp; backwards steps that add up ----------------------

TEST(IoRobustness, CorruptFirstTimestampIsAnOutlierNotTheReference) {
  TempDir d;
  std::string text = "10000000 5 5 1\n";
  for (int i = 0; i < 2000; ++i) text += std::to_string(1.0 + i * 1e-3) + " " + std::to_string(i % 240) + " 7 1\n";
  writeBytes(d.file("e.txt"), text);
  for (BackwardsPolicy policy : {BackwardsPolicy::Error, BackwardsPolicy::Drop, BackwardsPolicy::Sort}) {
    ReaderOptions o;
    o.backwards = policy;
    auto r = openEventSource(d.file("e.txt"), o);
    const auto ev = readAllEvents(*r);
    ASSERT_EQ(ev.size(), 2000u) << toString(policy);  // the bogus first event dropped, every good one kept
    EXPECT_DOUBLE_EQ(ev.front().t, 1.0);
    EXPECT_EQ(r->warnings().time_outliers, 1u);
    EXPECT_EQ(r->warnings().backwards_time, 0u);
    ASSERT_FALSE(r->warnings().messages.empty());
    EXPECT_NE(r->warnings().messages[0].find("e.txt: line 1: timestamp 1e+07 s of the first event"),
              std::string::npos) << r->warnings().messages[0];
  }
  EXPECT_IO_ERROR(celc::test::drain(d.file("e.txt"), strictOptions()), "line 1", "first event", "outlier");
  // The second event far back, the third near the first: the second is the outlier.
  writeBytes(d.file("s.txt"), "100.0 1 1 1\n50.0 1 1 1\n100.001 1 1 1\n100.002 1 1 1\n");
  auto s = openEventSource(d.file("s.txt"));
  const auto sv = readAllEvents(*s);
  ASSERT_EQ(sv.size(), 3u);
  EXPECT_DOUBLE_EQ(sv[0].t, 100.0);
  EXPECT_EQ(s->warnings().time_outliers, 1u);
  EXPECT_NE(s->warnings().messages.at(0).find("line 2"), std::string::npos) << s->warnings().messages.at(0);
  // AEDAT 2.0 whose first timestamp word is 0xFFFFFFFF: not taken for a wrap-around of the good ones.
  const auto ev = celc::test::randomEvents(3000, 240, 180, 5, 1.0);
  writeAedat2(d.file("a.aedat"), ev, {});
  std::string b = readBytes(d.file("a.aedat"));
  const std::size_t data = b.size() - 8 * ev.size();
  putBE32(b, data + 4, 0xFFFFFFFFu);
  writeBytes(d.file("f.aedat"), b);
  ReaderOptions drop;
  drop.backwards = BackwardsPolicy::Drop;
  auto a = openEventSource(d.file("f.aedat"), drop);
  const auto got = readAllEvents(*a);
  ASSERT_EQ(got.size(), ev.size() - 1);
  EXPECT_EQ(got.front().t, ev[1].t);
  EXPECT_EQ(got.back().t, ev.back().t);  // nothing shifted by 2^32 us
  EXPECT_EQ(a->warnings().time_outliers, 1u);
  EXPECT_EQ(a->warnings().backwards_dropped, 0u);
  EXPECT_NE(a->warnings().messages.at(0).find("byte " + std::to_string(data)), std::string::npos)
      << a->warnings().messages.at(0);
}

TEST(IoRobustness, BackwardsToleranceIsCumulativeNotPerStep) {
  // 0.9 ms back per event for 9 s: every step is within the 1 ms tolerance, the walk is not.
  TempDir d;
  std::string text;
  for (int i = 0; i < 10000; ++i) {
    char line[64];
    std::snprintf(line, sizeof line, "%.6f 1 2 1\n", 10.0 - i * 0.9e-3);
    text += line;
  }
  writeBytes(d.file("w.txt"), text);
  EXPECT_IO_ERROR(celc::test::drain(d.file("w.txt")), "w.txt: line 3", "0.0018 s before the latest event so far",
                  "input.backwards_tolerance");
  ReaderOptions drop;
  drop.backwards = BackwardsPolicy::Drop;
  auto r = openEventSource(d.file("w.txt"), drop);
  EXPECT_EQ(readAllEvents(*r).size(), 2u);
  EXPECT_EQ(r->warnings().backwards_dropped, 9998u);
  // Jitter within the tolerance around a rising time is kept, as before.
  writeBytes(d.file("j.txt"), "1.0000 1 1 1\n1.0010 1 1 1\n1.0005 1 1 1\n1.0008 1 1 1\n1.0020 1 1 1\n");
  auto j = openEventSource(d.file("j.txt"));
  EXPECT_EQ(readAllEvents(*j).size(), 5u);
  EXPECT_EQ(j->warnings().backwards_time, 2u);
}

// ---- HDF5: dataset types and values checked as stored ----------------------------

TEST(IoRobustness, Hdf5DatasetTypesAndValuesAreCheckedBeforeConversion) {
  TempDir d;
  // one DSEC column: writes its values into the named dataset
  using Column = std::function<void(celc::test::h5::File&, const std::string&)>;
  const auto column = [](auto values) -> Column {
    return [values](celc::test::h5::File& f, const std::string& name) { f.write(name, values); };
  };
  auto dsec = [&](const std::string& name, const Column& x, const Column& y, const Column& t, const Column& p) {
    celc::test::h5::File f(d.file(name));
    x(f, "events/x");
    y(f, "events/y");
    t(f, "events/t");
    p(f, "events/p");
    return true;
  };
  const Column x = column(range<std::uint16_t>(6)), y = column(range<std::int32_t>(6)),
               t = column(range<std::int64_t>(6, 0, 10)), p = column(std::vector<std::uint8_t>{0, 1, 1, 0, 1, 0});
  ASSERT_TRUE(dsec("ok.h5", x, y, t, p));
  {
    auto r = openEventSource(d.file("ok.h5"));
    const auto ev = readAllEvents(*r);
    ASSERT_EQ(ev.size(), 6u);
    EXPECT_EQ(ev[5].y, 5.0f);
    EXPECT_DOUBLE_EQ(ev[5].t, 50e-6);
    EXPECT_TRUE(ev[1].on);
    EXPECT_FALSE(ev[3].on);
  }
  ASSERT_TRUE(dsec("tf.h5", x, y, column(range<double>(6, 0.0, 0.01)), p));  // float64 seconds
  EXPECT_IO_ERROR(openEventSource(d.file("tf.h5")), "tf.h5: dataset /events/t: type float64, expected integers",
                  "microseconds as integers");
  ASSERT_TRUE(dsec("yn.h5", x, column(std::vector<std::int32_t>{0, 1, 2, -5, 4, 5}), t, p));
  EXPECT_IO_ERROR(celc::test::drain(d.file("yn.h5")), "yn.h5: dataset /events/y: row 3: value -5 outside [0, 65535]");
  ASSERT_TRUE(dsec("yb.h5", x, column(std::vector<std::int32_t>{0, 1, 70000, 3, 4, 5}), t, p));
  EXPECT_IO_ERROR(celc::test::drain(d.file("yb.h5")), "yb.h5: dataset /events/y: row 2: value 70000 outside");
  ASSERT_TRUE(dsec("pf.h5", x, y, t, column(std::vector<float>{0, 0.9f, 1, 0, 1, 0})));
  EXPECT_IO_ERROR(openEventSource(d.file("pf.h5")), "pf.h5: dataset /events/p: type float32, expected integers");
  ASSERT_TRUE(dsec("p7.h5", x, y, t, column(std::vector<std::uint8_t>{0, 1, 7, 0, 1, 0})));
  EXPECT_IO_ERROR(celc::test::drain(d.file("p7.h5")), "p7.h5: dataset /events/p: row 2: polarity 7 (expected 0 or 1)");
  const Column strings = [](celc::test::h5::File& f, const std::string& name) {
    f.writeStrings(name, {"1", "2", "3", "4", "5", "6"});
  };
  ASSERT_TRUE(dsec("xs.h5", strings, y, t, p));
  EXPECT_IO_ERROR(openEventSource(d.file("xs.h5")),
                  "xs.h5: dataset /events/x: type variable-length string, expected integers");
  // MVSEC: N x 4 numbers, polarity -1 / 1 (0 read as OFF); 0.9 is not a polarity.
  {
    auto ev = mvsecEvents(5, 1.0, 1e-3);
    ev[4 * 3 + 3] = 0.9;
    celc::test::h5::File f(d.file("mp.h5"));
    f.write("davis/left/events", ev, {5, 4});
  }
  EXPECT_IO_ERROR(celc::test::drain(d.file("mp.h5")), "mp.h5: dataset /davis/left/events, event 3: polarity 0.9");
  {
    celc::test::h5::File f(d.file("ms.h5"));
    f.writeFixedStrings("davis/left/events", {"a", "b"}, 1);
  }
  EXPECT_IO_ERROR(openEventSource(d.file("ms.h5")), "ms.h5: dataset /davis/left/events: type string of 1 bytes");
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

TEST(IoRobustness, HeldEventsNeverMakeABatchLargerThanItsMax) {
  // A held first event, an outlier, a gap and the end of the stream: every
  // batch size gives the same events, none more than its max.
  TempDir d;
  writeBytes(d.file("e.txt"), "100.0 1 1 1\n50.0 1 1 1\n100.001 1 1 1\n100.002 1 1 1\n500.0 1 1 1\n"
                              "100.003 1 1 1\n200.0 1 1 1\n200.001 1 1 1\n900.0 1 1 1\n");
  auto whole = openEventSource(d.file("e.txt"));
  const auto all = readAllEvents(*whole);
  ASSERT_EQ(all.size(), 7u);  // 50.0 and 500.0 dropped; the gap to 200 and the jump to 900 at the end kept
  for (std::size_t max : {1u, 2u, 3u}) {
    auto r = openEventSource(d.file("e.txt"));
    std::vector<Event> got, b;
    while (r->next(b, max)) {
      ASSERT_LE(b.size(), max);
      got.insert(got.end(), b.begin(), b.end());
    }
    ASSERT_EQ(got.size(), all.size()) << max;
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].t, all[i].t) << max << " " << i;
  }
}
