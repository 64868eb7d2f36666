// `celc info` end to end: what it prints for a generated file, and a one-line
// error with a non-zero exit status for a bad one.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sys/wait.h>

#include "celc/io/writers.hpp"
#include "io_test_util.hpp"

using namespace celc;
using celc::test::TempDir;

namespace {
int run(const std::string& cmd, std::string& out) {
  out.clear();
  std::FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return -1;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int st = ::pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
}  // namespace

TEST(IoCli, InfoPrintsCountsAndRates) {
  TempDir d;
  auto ev = celc::test::randomEvents(3000, 240, 180, 9, 5.0);
  auto imu = celc::test::randomImu(ev.front().t, ev.back().t, 10);
  writeAedat4(d.file("a.aedat4"), ev, imu, 240, 180, Aedat4Compression::Zstd, 1000, true);
  std::size_t on = 0;
  for (const auto& e : ev) on += e.on;
  std::string out;
  ASSERT_EQ(run(std::string(CELC_BINARY) + " info " + d.file("a.aedat4"), out), 0) << out;
  EXPECT_NE(out.find("format:        AEDAT 4.0"), std::string::npos) << out;
  EXPECT_NE(out.find("sensor:        240 x 180 px"), std::string::npos) << out;
  EXPECT_NE(out.find("events:        3000"), std::string::npos) << out;
  EXPECT_NE(out.find("(" + std::to_string(on) + " ON)"), std::string::npos) << out;
  EXPECT_NE(out.find("IMU samples:   " + std::to_string(imu.size())), std::string::npos) << out;
  EXPECT_NE(out.find("compression Zstd"), std::string::npos) << out;
}

TEST(IoCli, InfoBadFileIsOneLineErrorNonZeroExit) {
  TempDir d;
  celc::test::writeBytes(d.file("e.txt"), "0.1 1 2 1\n0.2 x 2 1\n");
  std::string out;
  EXPECT_NE(run(std::string(CELC_BINARY) + " info " + d.file("e.txt"), out), 0);
  EXPECT_NE(out.find("e.txt: line 2: non-numeric x"), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  celc::test::writeBytes(d.file("w.txt"), "0.2 1 2 1\n0.1995 1 2 1\n");  // within input.backwards_tolerance
  ASSERT_EQ(run(std::string(CELC_BINARY) + " info " + d.file("w.txt"), out), 0) << out;
  EXPECT_NE(out.find("timestamps backwards 1"), std::string::npos) << out;
  EXPECT_NE(out.find("time jumps and gaps 0, truncated end 0"), std::string::npos) << out;
  EXPECT_NE(run(std::string(CELC_BINARY) + " info --strict " + d.file("w.txt"), out), 0);
  // One outlier timestamp (1e7 s) among 1 ms steps: dropped, counted as a time jump.
  std::string jump;
  for (int i = 0; i < 50; ++i) jump += std::to_string(1.0 + i * 1e-3) + " 1 2 1\n" + (i == 20 ? "10000000 1 2 1\n" : "");
  celc::test::writeBytes(d.file("j.txt"), jump);
  ASSERT_EQ(run(std::string(CELC_BINARY) + " info " + d.file("j.txt"), out), 0) << out;
  EXPECT_NE(out.find("time jumps and gaps 1,"), std::string::npos) << out;
  celc::test::writeBytes(d.file("b.txt"), "0.2 1 2 1\n0.1 1 2 1\n");  // beyond it: an error naming the line
  EXPECT_NE(run(std::string(CELC_BINARY) + " info " + d.file("b.txt"), out), 0);
  EXPECT_NE(out.find("b.txt: line 2: timestamp"), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

TEST(IoCli, InfoPrintsEachWarningCountOnItsOwnLine) {
  TempDir d;
  // 1 ms steps with: a step back within the tolerance (kept), one beyond it (sorted
  // or dropped), an outlier at 30 s (dropped), a pixel outside 240x180 (dropped) and
  // a confirmed gap to 20 s (kept).
  celc::test::writeBytes(d.file("w.txt"),
                         "1.000 1 1 1\n1.001 2 2 0\n1.0015 3 3 1\n1.0012 4 4 1\n1.002 5 5 0\n1.000 6 6 1\n"
                         "1.003 7 7 1\n30.0 8 8 1\n1.004 9 9 0\n1.0055 300 9 1\n1.006 10 10 1\n20.0 11 11 1\n"
                         "20.001 12 12 0\n20.002 13 13 1\n");
  const std::string base = std::string(CELC_BINARY) + " info --width 240 --height 180 " + d.file("w.txt");
  std::string out;
  ASSERT_EQ(run(base + " --backwards sort", out), 0) << out;
  EXPECT_NE(out.find("events:        12\n"), std::string::npos) << out;
  EXPECT_NE(out.find("time jumps:    2 (outliers dropped 1, gaps kept 1; input.max_time_jump = 10 s)"),
            std::string::npos) << out;
  EXPECT_NE(out.find("backwards:     2 (kept within input.backwards_tolerance 1, sorted 1, dropped 0)"),
            std::string::npos) << out;
  EXPECT_NE(out.find("outside:       1 events with a pixel outside the sensor (dropped)"), std::string::npos) << out;
  EXPECT_NE(out.find("truncated:     no\n"), std::string::npos) << out;
  ASSERT_EQ(run(base + " --backwards drop", out), 0) << out;
  EXPECT_NE(out.find("events:        11\n"), std::string::npos) << out;
  EXPECT_NE(out.find("backwards:     2 (kept within input.backwards_tolerance 1, sorted 0, dropped 1)"),
            std::string::npos) << out;
  // A larger bound: the outlier and the gap are ordinary steps.
  ASSERT_EQ(run(base + " --backwards drop --max-time-jump 100", out), 0) << out;
  EXPECT_NE(out.find("time jumps:    0 (outliers dropped 0, gaps kept 0; input.max_time_jump = 100 s)"),
            std::string::npos) << out;
  EXPECT_NE(run(base, out), 0);  // the default policy: the step back beyond the tolerance is an error
  EXPECT_NE(out.find("w.txt: line 6: timestamp"), std::string::npos) << out;

  // An AEDAT 2.0 file cut 3 bytes into its last 8-byte record: the byte where it ends.
  auto ev = celc::test::randomEvents(100, 240, 180, 4, 2.0);
  writeAedat2(d.file("cut.aedat"), ev, {});
  std::string bytes;
  {
    std::ifstream in(d.file("cut.aedat"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  bytes.resize(bytes.size() - 5);
  celc::test::writeBytes(d.file("cut.aedat"), bytes);
  ASSERT_EQ(run(std::string(CELC_BINARY) + " info " + d.file("cut.aedat"), out), 0) << out;
  EXPECT_NE(out.find("events:        99\n"), std::string::npos) << out;
  EXPECT_NE(out.find("truncated:     yes: the file ends at byte " + std::to_string(bytes.size()) + " inside"),
            std::string::npos) << out;
}
