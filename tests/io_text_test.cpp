// Text readers: events.txt / imu.txt / groundtruth.txt variants and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "celc/io/text_io.hpp"
#include "celc/io/writers.hpp"
#include "io_test_util.hpp"

using namespace celc;
using namespace celc;
using celc::test::expectPrintable;
using celc::test::ioErrorOf;
using celc::test::putBE32;
using celc::test::readBytes;
using celc::test::strictOptions;
using celc::test::TempDir;
using celc::test::writeBytes;

namespace {
void expectSameEvents(const std::vector<Event>& a, const std::vector<Event>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i].t, b[i].t, 1e-9) << i;  // written with 9 decimals
    EXPECT_EQ(a[i].x, b[i].x) << i;
    EXPECT_EQ(a[i].y, b[i].y) << i;
    EXPECT_EQ(a[i].on, b[i].on) << i;
  }
}
}  // namespace

TEST(IoText, EventsRoundTripAllVariants) {
  TempDir d;
  const auto ev = celc::test::randomEvents(5000, 240, 180, 1);
  struct V { bool crlf, id, final_nl; std::string header; };
  const V variants[] = {{false, false, true, ""}, {true, false, true, ""}, {false, false, false, ""},
                        {true, true, false, ""},  {false, false, true, "t x y p"},
                        {false, true, true, "id timestamp x y polarity"}};
  for (const V& v : variants) {
    TextWriteOptions o;
    o.crlf = v.crlf, o.id_column = v.id, o.final_newline = v.final_nl, o.header = v.header;
    writeEventsText(d.file("e.txt"), ev, o);
    auto r = openEventSource(d.file("e.txt"));
    EXPECT_EQ(r->format(), Format::Text);
    expectSameEvents(readAllEvents(*r), ev);
    EXPECT_EQ(r->warnings().total(), 0u);
  }
}

TEST(IoText, HeaderGivesColumnOrderAndCommasAndSmallBatches) {
  TempDir d;
  celc::test::writeBytes(d.file("e.csv"), "x,y,p,t\n3,4,1,0.5\n5,6,0,0.75\r\n");
  auto r = openEventSource(d.file("e.csv"));
  std::vector<Event> b;
  ASSERT_TRUE(r->next(b, 1));
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].t, 0.5);
  EXPECT_EQ(b[0].x, 3.0f);
  EXPECT_EQ(b[0].y, 4.0f);
  EXPECT_TRUE(b[0].on);
  ASSERT_TRUE(r->next(b, 10));
  EXPECT_EQ(b[0].t, 0.75);
  EXPECT_FALSE(b[0].on);
  EXPECT_FALSE(r->next(b, 10));
  EXPECT_TRUE(b.empty());
}

TEST(IoText, PolarityMinusOneAndTimeScale) {
  TempDir d;
  celc::test::writeBytes(d.file("e.txt"), "1000 1 2 -1\n2000 1 2 1\n");
  ReaderOptions o;
  o.text_time_scale = 1e-6;
  auto r = openEventSource(d.file("e.txt"), o);
  auto ev = readAllEvents(*r);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_FALSE(ev[0].on);
  EXPECT_DOUBLE_EQ(ev[1].t, 2e-3);
}

TEST(IoText, ImuColumnOrders) {
  TempDir d;
  auto imu = celc::test::randomImu(1.0, 1.05, 2);
  // RPG: t ax ay az gx gy gz
  writeImuText(d.file("rpg.txt"), imu, false);
  // UZH-FPV: id t wx wy wz ax ay az with header
  TextWriteOptions u;
  u.id_column = true;
  u.header = "id timestamp ang_vel_x ang_vel_y ang_vel_z lin_acc_x lin_acc_y lin_acc_z";
  writeImuText(d.file("uzh.txt"), imu, true, u);
  // gyro first, no header, no id: needs the option
  writeImuText(d.file("gf.txt"), imu, true);
  // 8 columns without header: id + gyro first by default
  TextWriteOptions id;
  id.id_column = true;
  writeImuText(d.file("id8.txt"), imu, true, id);
  ReaderOptions gf;
  gf.imu_columns = ImuColumns::GyroFirst;
  for (auto [path, opt] : {std::pair{d.file("rpg.txt"), ReaderOptions{}}, std::pair{d.file("uzh.txt"), ReaderOptions{}},
                           std::pair{d.file("gf.txt"), gf}, std::pair{d.file("id8.txt"), ReaderOptions{}}}) {
    auto got = readImuText(path, opt);
    ASSERT_EQ(got.size(), imu.size()) << path;
    for (std::size_t i = 0; i < imu.size(); ++i) {
      EXPECT_NEAR(got[i].t, imu[i].t, 1e-9);
      EXPECT_LT((got[i].gyro - imu[i].gyro).norm(), 1e-7) << path << " " << i;
      EXPECT_LT((got[i].accel - imu[i].accel).norm(), 1e-6) << path << " " << i;
    }
  }
  // the same gyro-first file read with the RPG order swaps the vectors: the option matters
  auto wrong = readImuText(d.file("gf.txt"));
  EXPECT_GT((wrong[0].gyro - imu[0].gyro).norm(), 1e-3);
}

TEST(IoText, RpgDirectoryWithImu) {
  TempDir d;
  const auto ev = celc::test::randomEvents(100, 240, 180, 3, 1.0);
  writeEventsText(d.file("events.txt"), ev);
  writeImuText(d.file("imu.txt"), celc::test::randomImu(1.0, 1.01, 4), false);
  const std::string dir = d.file("");
  EXPECT_EQ(detectFormat(dir), Format::RpgDirectory);
  auto r = openEventSource(dir);
  EXPECT_EQ(readAllEvents(*r).size(), 100u);
  EXPECT_EQ(r->readImu().size(), 10u);
}

TEST(IoText, PosesWithAndWithoutId) {
  TempDir d;
  std::vector<PoseSample> poses(20);
  for (int i = 0; i < 20; ++i) {
    poses[std::size_t(i)].t = 0.01 * i;
    poses[std::size_t(i)].position = Vec3(i, -i, 0.5 * i);
    poses[std::size_t(i)].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Vec3::UnitZ()));
  }
  writePosesText(d.file("gt.txt"), poses);
  TextWriteOptions o;
  o.id_column = true;
  o.header = "id timestamp tx ty tz qx qy qz qw";
  writePosesText(d.file("gt_id.txt"), poses, o);
  for (const auto& p : {d.file("gt.txt"), d.file("gt_id.txt")}) {
    auto got = readPosesText(p);
    ASSERT_EQ(got.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_LT((got[i].position - poses[i].position).norm(), 1e-9);
      EXPECT_LT(got[i].orientation.angularDistance(poses[i].orientation), 1e-9);
    }
  }
}

// ---- bad input -------------------------------------------------------------

// A text file a reader refuses: its name and content, the reader (events,
// IMU or poses), and the fragments of the one-line error (with the file's
// path when `names_path`).
struct TextRefusal {
  const char* label;
  const char* file;
  const char* content;
  enum Reader { Events, Imu, Poses } reader;
  std::vector<std::string> fragments;
  bool names_path = false;
};
class IoTextBadFile : public ::testing::TestWithParam<TextRefusal> {};

TEST_P(IoTextBadFile, RefusedWithItsLineAndReason) {
  TempDir d;
  const TextRefusal& c = GetParam();
  celc::test::writeBytes(d.file(c.file), c.content);
  std::vector<std::string> fragments = c.fragments;
  if (c.names_path) fragments.insert(fragments.begin(), d.file(c.file));
  switch (c.reader) {
    case TextRefusal::Events:
      EXPECT_IO_ERROR(celc::test::drain(d.file(c.file)), fragments);
      break;
    case TextRefusal::Imu:
      EXPECT_IO_ERROR(readImuText(d.file(c.file)), fragments);
      break;
    case TextRefusal::Poses:
      EXPECT_IO_ERROR(readPosesText(d.file(c.file)), fragments);
      break;
  }
}

INSTANTIATE_TEST_SUITE_P(
    IoTextBad, IoTextBadFile,
    ::testing::Values(
        // non-numeric fields name the file and the line
        TextRefusal{"non_numeric_x", "e.txt", "0.1 1 2 1\n0.2 1 2 1\n0.3 abc 2 1\n", TextRefusal::Events,
                    {"line 3", "non-numeric x"}, true},
        TextRefusal{"non_numeric_time", "t.txt", "0.1 1 2 1\n0.2x 1 2 1\n", TextRefusal::Events,
                    {"line 2", "timestamp"}},
        TextRefusal{"nan_time", "n.txt", "nan 1 2 1\n", TextRefusal::Events, {"line 1", "timestamp"}},
        // wrong column counts
        TextRefusal{"short_row", "a.txt", "0.1 1 2 1\n0.2 1 2\n", TextRefusal::Events,
                    {"line 2", "expected 4 columns, found 3"}},
        TextRefusal{"three_columns", "b.txt", "0.1 1 2\n", TextRefusal::Events,
                    {"line 1", "unsupported column count 3"}},
        TextRefusal{"eighteen_columns", "c.txt", "0.1 1 2 1 5 6 7 8 9 10 11 12 13 14 15 16 17 18\n",
                    TextRefusal::Events, {"line 1", "column count"}},
        TextRefusal{"imu_short_row", "imu.txt", "0.1 1 2 3 4 5 6\n0.2 1 2 3 4 5\n", TextRefusal::Imu,
                    {"imu.txt: line 2", "expected 7 columns"}},
        TextRefusal{"poses_seven_columns", "gt.txt", "0.1 1 2 3 0 0 0\n", TextRefusal::Poses,
                    {"gt.txt: line 1", "column count 7"}},
        // polarity, header, quaternion
        TextRefusal{"polarity_two", "p.txt", "0.1 1 2 2\n", TextRefusal::Events, {"line 1", "polarity"}},
        TextRefusal{"unknown_header", "h.txt", "time col row sign\n0.1 1 2 1\n", TextRefusal::Events,
                    {"line 1", "header"}},
        TextRefusal{"zero_quaternion", "q.txt", "0.1 0 0 0 0 0 0 0\n", TextRefusal::Poses,
                    {"line 1", "zero quaternion"}},
        TextRefusal{"poses_backwards", "qt.txt", "0.2 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n", TextRefusal::Poses,
                    {"line 2", "increase"}}),
    [](const ::testing::TestParamInfo<TextRefusal>& i) { return std::string(i.param.label); });

TEST(IoTextBad, BackwardsTimestampsCountedOrStrict) {
  TempDir d;
  celc::test::writeBytes(d.file("e.txt"), "0.1 1 2 1\n0.3 1 2 1\n0.2 1 2 1\n0.4 1 2 1\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("e.txt")), "line 3", "before the latest event so far");  // beyond 1 ms
  ReaderOptions tolerant;
  tolerant.backwards_tolerance = 0.5;
  auto r = openEventSource(d.file("e.txt"), tolerant);
  EXPECT_EQ(readAllEvents(*r).size(), 4u);  // kept
  EXPECT_EQ(r->warnings().backwards_time, 1u);
  ASSERT_EQ(r->warnings().messages.size(), 1u);
  EXPECT_NE(r->warnings().messages[0].find("line 3"), std::string::npos);
  ReaderOptions strict = tolerant;
  strict.strict = true;
  EXPECT_IO_ERROR(celc::test::drain(d.file("e.txt"), strict), "line 3", "before the latest event so far");
}

TEST(IoTextBad, PixelsOutsideSensorDropped) {
  TempDir d;
  celc::test::writeBytes(d.file("e.txt"), "0.1 1 2 1\n0.2 240 2 1\n0.3 -1 2 1\n0.4 239 179 0\n");
  ReaderOptions o;
  o.width = 240;
  o.height = 180;
  auto r = openEventSource(d.file("e.txt"), o);
  EXPECT_EQ(readAllEvents(*r).size(), 2u);
  EXPECT_EQ(r->warnings().outside_sensor, 2u);
  // without a sensor size only negative pixels (and >= 65536) are outside
  auto r2 = openEventSource(d.file("e.txt"));
  EXPECT_EQ(readAllEvents(*r2).size(), 3u);
  celc::test::writeBytes(d.file("huge.txt"), "0.1 1e30 2 1\n0.2 1.5 2.5 1\n");
  auto r3 = openEventSource(d.file("huge.txt"));
  auto ev = readAllEvents(*r3);
  ASSERT_EQ(ev.size(), 1u);  // sub-pixel coordinates (simulators) are kept as floats
  EXPECT_EQ(ev[0].x, 1.5f);
  EXPECT_EQ(r3->warnings().outside_sensor, 1u);
}

TEST(IoTextBad, EmptyMissingBinaryAndHugeLine) {
  TempDir d;
  celc::test::writeBytes(d.file("empty.txt"), "");
  auto r = openEventSource(d.file("empty.txt"));
  std::vector<Event> b;
  EXPECT_FALSE(r->next(b, 10));
  EXPECT_IO_ERROR(openEventSource(d.file("missing.txt")), "missing.txt", "cannot open");
  std::filesystem::create_directories(d.file("nodir"));
  EXPECT_IO_ERROR(openEventSource(d.file("nodir")), "nodir", "without events.txt");
  celc::test::writeBytes(d.file("bin.dat"), std::string("\x01\x00\x02\x03", 4));
  EXPECT_IO_ERROR(openEventSource(d.file("bin.dat")), "byte 0", "binary");
  celc::test::writeBytes(d.file("long.txt"), std::string(5u << 20, '1'));
  EXPECT_IO_ERROR(celc::test::drain(d.file("long.txt")), "line 1", "longer than");
  ReaderOptions bad;
  bad.width = 10;  // height missing
  EXPECT_IO_ERROR(openEventSource(d.file("empty.txt"), bad), "invalid reader options");
}

TEST(IoTextConformance, EcdSlices) {
  for (const char* seq : {"boxes_rotation", "boxes_translation", "poster_translation", "shapes_translation"}) {
    const std::string dir = celc::test::sharedData(std::string("ecd_slices/") + seq);
    SKIP_IF_NO_SHARED(dir);
    ReaderOptions o;
    o.width = 240;
    o.height = 180;
    auto r = openEventSource(dir, o);
    auto ev = readAllEvents(*r);
    EXPECT_EQ(ev.size(), 30000u) << seq;
    EXPECT_EQ(r->warnings().total(), 0u) << seq;
  }
  const std::string dir = celc::test::sharedData("ecd_slices/boxes_translation");
  auto r = openEventSource(dir);
  auto ev = readAllEvents(*r);
  EXPECT_NEAR(ev.front().t, 18.5799, 1e-4);  // README: boxes_translation starts at t = 18.5799 s
}

// CR-only line endings (classic Mac) read as one line: named as such, not
// as an unsupported column count.
TEST(IoText, CrOnlyLineEndingsAreNamed) {
  TempDir d;
  for (int lines : {3, 40}) {
    {
      std::ofstream f(d.file("cr.txt"), std::ios::binary);
      for (int i = 0; i < lines; ++i) f << 0.001 * i << " " << i % 200 << " 7 " << i % 2 << "\r";
    }
    std::string m;
    try {
      auto r = openEventSource(d.file("cr.txt"));
      readAllEvents(*r);
    } catch (const IoError& e) {
      m = e.what();
    }
    EXPECT_NE(m.find("cr.txt: line 1: line endings are CR only"), std::string::npos) << lines << " lines: " << m;
  }
  // CRLF files still read.
  {
    std::ofstream f(d.file("crlf.txt"), std::ios::binary);
    for (int i = 0; i < 5; ++i) f << 0.001 * i << " " << i << " 7 1\r\n";
  }
  auto r = openEventSource(d.file("crlf.txt"));
  EXPECT_EQ(readAllEvents(*r).size(), 5u);
}

// ---- malformed and hostile inputs (docs/robustness.md's table) -------------------

// ---- messages never echo raw bytes ---------------------------------------------

TEST(IoRobustness, MessagesArePrintableOneLine) {
  TempDir d;
  std::vector<std::string> messages;
  // control bytes and an ANSI escape in a field
  writeBytes(d.file("c.txt"), std::string("0.1\x01\x1b[31m 1 2 1\n"));
  messages.push_back(ioErrorOf([&] { celc::test::drain(d.file("c.txt")); }));
  // invalid UTF-8 in a header line (after a valid first block, so detection passes)
  writeBytes(d.file("u.txt"), std::string("0.1 1 2 1\ntime col\xff\xfe row sign\n"));
  messages.push_back(ioErrorOf([&] { celc::test::drain(d.file("u.txt")); }));
  // a field with a carriage return inside the line
  writeBytes(d.file("r.txt"), std::string("0.1 1 2 1\n0.2 1\r2 1 1\n"));
  messages.push_back(ioErrorOf([&] { celc::test::drain(d.file("r.txt")); }));
  // an AEDAT version "line" that spans two lines and holds control bytes
  writeBytes(d.file("v.aedat"), std::string("#!AER-DAT9.9\rsecond line\n\x07\x1b[2J"));
  messages.push_back(ioErrorOf([&] { openEventSource(d.file("v.aedat")); }));
  // AEDAT 2.0 / 3.1 magic lines with junk
  writeBytes(d.file("m2.aedat"), std::string("#!AER-DAT2.0\x1b[0m\xff\r\n"));
  messages.push_back(ioErrorOf([&] { openEventSource(d.file("m2.aedat")); }));
  writeBytes(d.file("m3.aedat"), std::string("#!AER-DAT3.1\x01\x02\xc3\x28\r\n"));
  messages.push_back(ioErrorOf([&] { openEventSource(d.file("m3.aedat")); }));
  // an AEDAT 2.0 chip name with control bytes: the note and the error are printable
  writeBytes(d.file("chip.aedat"), std::string("#!AER-DAT2.0\r\n# AEChip: x.\x1b]0;DVS128\x07\r\n"));
  messages.push_back(ioErrorOf([&] { openEventSource(d.file("chip.aedat")); }));
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
  std::string m = ioErrorOf([&] { openEventSource(d.file("r.bin")); });
  expectPrintable(m);
  EXPECT_NE(m.find("binary data"), std::string::npos) << m;
  EXPECT_LT(m.size(), 200u) << m;
  // bytes >= 0x80 only (no control byte at all): invalid UTF-8 is binary too
  std::string h;
  for (int i = 0; i < 4096; ++i) h.push_back(char(0x80 | (rng() & 0x7F)));
  writeBytes(d.file("h.bin"), "0.1 1 2 1\n" + h);
  m = ioErrorOf([&] { openEventSource(d.file("h.bin")); });
  EXPECT_NE(m.find("binary data"), std::string::npos) << m;
  expectPrintable(m);
  // UTF-8 text in a comment is still text
  writeBytes(d.file("t.txt"), "# t [\xc2\xb5s] x y p\n0.1 1 2 1\n");
  EXPECT_EQ(detectFormat(d.file("t.txt")), Format::Text);
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
