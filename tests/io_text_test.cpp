// Text readers: events.txt / imu.txt / groundtruth.txt variants and bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "celc/io/text_io.hpp"
#include "celc/io/writers.hpp"
#include "io_test_util.hpp"

using namespace celc;
using namespace celc;
using celc::test::TempDir;

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

TEST(IoTextBad, NonNumericFieldNamesFileAndLine) {
  TempDir d;
  celc::test::writeBytes(d.file("e.txt"), "0.1 1 2 1\n0.2 1 2 1\n0.3 abc 2 1\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("e.txt")), d.file("e.txt"), "line 3", "non-numeric x");
  celc::test::writeBytes(d.file("t.txt"), "0.1 1 2 1\n0.2x 1 2 1\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("t.txt")), "line 2", "timestamp");
  celc::test::writeBytes(d.file("n.txt"), "nan 1 2 1\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("n.txt")), "line 1", "timestamp");
}

TEST(IoTextBad, WrongColumnCounts) {
  TempDir d;
  celc::test::writeBytes(d.file("a.txt"), "0.1 1 2 1\n0.2 1 2\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("a.txt")), "line 2", "expected 4 columns, found 3");
  celc::test::writeBytes(d.file("b.txt"), "0.1 1 2\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("b.txt")), "line 1", "unsupported column count 3");
  celc::test::writeBytes(d.file("c.txt"), "0.1 1 2 1 5 6 7 8 9 10 11 12 13 14 15 16 17 18\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("c.txt")), "line 1", "column count");
  celc::test::writeBytes(d.file("imu.txt"), "0.1 1 2 3 4 5 6\n0.2 1 2 3 4 5\n");
  EXPECT_IO_ERROR(readImuText(d.file("imu.txt")), "imu.txt: line 2", "expected 7 columns");
  celc::test::writeBytes(d.file("gt.txt"), "0.1 1 2 3 0 0 0\n");
  EXPECT_IO_ERROR(readPosesText(d.file("gt.txt")), "gt.txt: line 1", "column count 7");
}

TEST(IoTextBad, BadPolarityHeaderAndQuaternion) {
  TempDir d;
  celc::test::writeBytes(d.file("p.txt"), "0.1 1 2 2\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("p.txt")), "line 1", "polarity");
  celc::test::writeBytes(d.file("h.txt"), "time col row sign\n0.1 1 2 1\n");
  EXPECT_IO_ERROR(celc::test::drain(d.file("h.txt")), "line 1", "header");
  celc::test::writeBytes(d.file("q.txt"), "0.1 0 0 0 0 0 0 0\n");
  EXPECT_IO_ERROR(readPosesText(d.file("q.txt")), "line 1", "zero quaternion");
  celc::test::writeBytes(d.file("qt.txt"), "0.2 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n");
  EXPECT_IO_ERROR(readPosesText(d.file("qt.txt")), "line 2", "increase");
}

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
