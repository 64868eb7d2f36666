// The sequence directory layout (io/sequence_layout.hpp) and the events text
// line formatters (io/writers.hpp).
#include <gtest/gtest.h>

#include <string>

#include "celc/io/sequence_layout.hpp"
#include "celc/io/writers.hpp"
#include "io_test_util.hpp"

using namespace celc;
using namespace celc;

TEST(SequenceLayout, FindsTheFilesAndPrefersCalibYaml) {
  celc::test::TempDir d;
  const std::string dir = d.file("");
  EXPECT_FALSE(isSequenceDirectory(dir));
  EXPECT_TRUE(resolveSequenceLayout(dir).events.empty());
  celc::test::writeBytes(d.file("events.txt"), "0.1 1 2 1\n");
  celc::test::writeBytes(d.file("calib.txt"), "1 1 1 1\n");
  EXPECT_TRUE(isSequenceDirectory(dir));
  SequenceLayout l = resolveSequenceLayout(dir);
  EXPECT_EQ(l.events, d.file("events.txt"));
  EXPECT_EQ(l.calib, d.file("calib.txt"));
  EXPECT_TRUE(l.imu.empty());
  EXPECT_TRUE(l.groundtruth.empty());
  celc::test::writeBytes(d.file("calib.yaml"), "fx: 1\n");
  celc::test::writeBytes(d.file("imu.txt"), "");
  celc::test::writeBytes(d.file("groundtruth.txt"), "");
  l = resolveSequenceLayout(dir);
  EXPECT_EQ(l.calib, d.file("calib.yaml"));
  EXPECT_EQ(l.imu, d.file("imu.txt"));
  EXPECT_EQ(l.groundtruth, d.file("groundtruth.txt"));
  EXPECT_FALSE(isSequenceDirectory(d.file("events.txt")));  // a file, not a directory
}

TEST(SequenceLayout, SimulatedFilesStartWithTheEvents) {
  const auto& files = simulatedSequenceFiles();
  ASSERT_FALSE(files.empty());
  EXPECT_STREQ(files.front(), sequence_file::kEvents);
  EXPECT_EQ(sequenceLayoutSummary(), "events.txt, imu.txt, groundtruth.txt, calib.yaml|calib.txt");
}

TEST(EventLine, SecondsAndMicroseconds) {
  char buf[128];
  const int n = formatEventLine(buf, sizeof buf, 1.5, 12, 7, true);
  EXPECT_EQ(std::string(buf, static_cast<std::size_t>(n)), "1.500000000 12 7 1");
  auto micros = [&](std::int64_t t_us, int x, int y, bool on) {
    char* end = putEventLineMicros(buf, t_us, x, y, on);
    return std::string(buf, end);
  };
  EXPECT_EQ(micros(1234567, 345, 259, false), "1.234567 345 259 0");
  EXPECT_EQ(micros(0, 0, 0, true), "0.000000 0 0 1");
  EXPECT_EQ(micros(42, 1, 2, true), "0.000042 1 2 1");
  EXPECT_EQ(micros(-1500000, 3, 4, false), "-1.500000 3 4 0");
}
