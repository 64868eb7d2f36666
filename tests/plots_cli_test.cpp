// The plots of `celc run`, `celc batch` and `celc table --plot` (scripts/plot_run.py).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_util.hpp"

namespace fs = std::filesystem;
using celc::test::readAll;
using celc::test::runCelc;

namespace {

const std::string kSample = CELC_SOURCE_DIR "/data/sample_seq";
// The sample's first 0.12 s: two windows of 50,000 events.
const std::string kFast = " --threads 2 --window-events 50000 --set windows.t_end=0.12 ";

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

// Debian's interpreter with matplotlib, as the binary uses it.
bool haveMatplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") == 0;
}

// scripts/setup.sh installs python3-matplotlib: its absence is a failure.
#define REQUIRE_MATPLOTLIB()                                                               \
  ASSERT_TRUE(haveMatplotlib()) << "/usr/bin/python3 cannot import matplotlib "                 \
                                   "(scripts/setup.sh installs python3-matplotlib)"

// A PNG file of some substance: the signature and more than SIZE bytes.
void expectPng(const fs::path& p, std::uintmax_t size = 10000) {
  ASSERT_TRUE(fs::exists(p)) << p;
  EXPECT_GT(fs::file_size(p), size) << p;
  std::ifstream in(p, std::ios::binary);
  std::string head(8, '\0');
  in.read(head.data(), 8);
  EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8)) << p;
}

}  // namespace

TEST(Plots, RunWritesVelocityAndErrorPng) {
  REQUIRE_MATPLOTLIB();
  const fs::path d = celc::test::freshTempDir("plots_run");
  const auto r = runCelc("run '" + kSample + "' -o " + q(d / "o") + kFast, d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  expectPng(d / "o" / "velocity.png");
  expectPng(d / "o" / "error.png");
  EXPECT_EQ(r.err.find("warn"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("velocity.png, error.png"), std::string::npos) << r.err;
  // --force replaces the run and its plots; --no-plots leaves none (not the old ones).
  const auto again = runCelc("run '" + kSample + "' -o " + q(d / "o") + kFast + "--force --no-plots", d, true);
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_TRUE(fs::exists(d / "o" / "windows.csv"));
  EXPECT_FALSE(fs::exists(d / "o" / "velocity.png"));
  EXPECT_FALSE(fs::exists(d / "o" / "error.png"));
  fs::remove_all(d);
}

TEST(Plots, NoPlotsFlagAndEnvironmentWriteNone) {
  // Needs no matplotlib: nothing is plotted.
  const fs::path d = celc::test::freshTempDir("plots_none");
  auto r = runCelc("run '" + kSample + "' -o " + q(d / "a") + kFast + "--no-plots", d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(d / "a" / "windows.csv"));
  EXPECT_FALSE(fs::exists(d / "a" / "velocity.png"));
  EXPECT_FALSE(fs::exists(d / "a" / "error.png"));
  r = runCelc("run '" + kSample + "' -o " + q(d / "b") + kFast, d, false);  // CELC_NO_PLOTS=1
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(d / "b" / "windows.csv"));
  EXPECT_FALSE(fs::exists(d / "b" / "velocity.png"));
  // celc batch --no-plots: neither the runs' plots nor table.png.
  std::ofstream(d / "batch.yaml") << "sequences:\n  - {label: a, path: '" << kSample << "', t_end: 0.12}\n";
  r = runCelc("batch " + q(d / "batch.yaml") + " -o " + q(d / "out") + " -q --no-plots" + kFast, d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(d / "out" / "a" / "windows.csv"));
  EXPECT_TRUE(fs::exists(d / "out" / "table.md"));
  EXPECT_FALSE(fs::exists(d / "out" / "a" / "velocity.png"));
  EXPECT_FALSE(fs::exists(d / "out" / "table.png"));
  fs::remove_all(d);
}

TEST(Plots, RunWithoutGroundTruthWritesVelocityOnly) {
  REQUIRE_MATPLOTLIB();
  const fs::path d = celc::test::freshTempDir("plots_nogt");
  // First with ground truth into the folder: its error.png must not survive the next run.
  auto r = runCelc("run '" + kSample + "' -o " + q(d / "o") + kFast, d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(d / "o" / "error.png"));
  // The sample's events, calibration and IMU as files: no ground truth.
  r = runCelc("run '" + kSample + "/events.txt' --calib '" + kSample + "/calib.yaml' --imu '" + kSample +
                  "/imu.txt' -o " + q(d / "o") + kFast + "--force",
              d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = readAll(d / "o" / "windows.csv");
  ASSERT_NE(csv.find(",ok,"), std::string::npos) << csv;
  expectPng(d / "o" / "velocity.png");
  EXPECT_FALSE(fs::exists(d / "o" / "error.png"));
  EXPECT_NE(r.err.find("no ground truth: no error.png"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("warn"), std::string::npos) << r.err;
  fs::remove_all(d);
}

namespace {

// Sets an environment variable for the life of the object.
struct ScopedEnv {
  std::string name;
  ScopedEnv(const std::string& n, const std::string& value) : name(n) { setenv(n.c_str(), value.c_str(), 1); }
  ~ScopedEnv() { unsetenv(name.c_str()); }
};

// A windows.csv of the first format (16 columns, no sigma_deg): two windows,
// celc ok in both, npt degenerate in the second; ground truth when `gt`.
void writeOldCsv(const fs::path& dir, bool gt) {
  fs::create_directories(dir);
  const std::string g = gt ? "0.8,0,0.6" : ",,";
  std::ofstream(dir / "windows.csv")
      << "window,t_start,t_end,n_events,n_clusters,method,status,vx,vy,vz,gt_vx,gt_vy,gt_vz,eps,phi,runtime_ms\n"
      << "0,0.0,0.1,1000,5,celc,ok,0.8,0.1,0.59," << g << (gt ? ",0.1,0.1," : ",,,") << "1.0\n"
      << "0,0.0,0.1,1000,5,npt,ok,0.7,0,0.71," << g << (gt ? ",0.15,0.15," : ",,,") << "0.5\n"
      << "1,0.1,0.2,1000,5,celc,ok,0.6,0,0.8," << g << (gt ? ",0.2,0.2," : ",,,") << "1.0\n"
      << "1,0.1,0.2,1000,5,npt,degenerate,,,," << g << ",,,0.5\n";
}

}  // namespace

TEST(Plots, FailedPlottingIsAOneLineWarning) {
  const fs::path d = celc::test::freshTempDir("plots_fail");
  const ScopedEnv env("CELC_PYTHON", "/bin/false");
  const auto r = runCelc("run '" + kSample + "' -o " + q(d / "o") + kFast, d, true);
  ASSERT_EQ(r.status, 0) << r.err;  // the run is the result; the plot is not
  EXPECT_TRUE(fs::exists(d / "o" / "summary.md"));
  EXPECT_FALSE(fs::exists(d / "o" / "velocity.png"));
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("plot_run.py failed"), std::string::npos) << r.err;
  // table --plot asked for the file: its failure is the command's error, after the table.
  const auto t = runCelc("table " + q(d / "o") + " --plot " + q(d / "t.png"), d, true);
  EXPECT_EQ(t.status, 1);
  EXPECT_NE(t.out.find("| o | eps"), std::string::npos) << t.out;
  EXPECT_NE(t.err.find("celc: error: --plot"), std::string::npos) << t.err;
  EXPECT_FALSE(fs::exists(d / "t.png"));
  fs::remove_all(d);
}

TEST(Plots, ScriptPlotsOldFilesAndSkipsErrorWithoutGroundTruth) {
  REQUIRE_MATPLOTLIB();
  const fs::path d = celc::test::freshTempDir("plots_script");
  writeOldCsv(d / "gt", true);
  writeOldCsv(d / "nogt", false);
  std::ofstream(d / "nogt" / "error.png") << "stale";
  const std::string script = CELC_SOURCE_DIR "/scripts/plot_run.py";
  ASSERT_EQ(std::system(("/usr/bin/python3 '" + script + "' " + q(d / "gt") + " " + q(d / "nogt")).c_str()), 0);
  expectPng(d / "gt" / "velocity.png");
  expectPng(d / "gt" / "error.png");
  expectPng(d / "nogt" / "velocity.png");
  EXPECT_FALSE(fs::exists(d / "nogt" / "error.png"));  // a stale plot goes
  // A folder without windows.csv: exit status 1 and one line.
  const fs::path err = d / "err.txt";
  EXPECT_NE(std::system(("/usr/bin/python3 '" + script + "' " + q(d / "none") + " 2> " + q(err)).c_str()), 0);
  const std::string msg = readAll(err);
  EXPECT_NE(msg.find("windows.csv: not found"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), msg.size() - 1) << msg;
  fs::remove_all(d);
}

TEST(Plots, TablePlotsRunsSideBySide) {
  REQUIRE_MATPLOTLIB();
  const fs::path d = celc::test::freshTempDir("plots_table");
  auto r = runCelc("run '" + kSample + "' -o " + q(d / "sample") + kFast + "--no-plots", d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  // A folder name that needs quoting for the shell; a run of the first format without ground truth.
  const fs::path odd = d / "old 'v1'";
  writeOldCsv(odd, true);
  writeOldCsv(d / "nogt", false);
  r = runCelc("table " + q(d / "sample") + " \"" + odd.string() + "\" --label 'no gt'=" + q(d / "nogt") +
                  " --plot " + q(d / "t.png"),
              d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| sample | eps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| old 'v1' | eps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| no gt | eps"), std::string::npos) << r.out;
  expectPng(d / "t.png");
  // With --max-sigma (the old files have no sigma_deg: none of their rows is kept).
  r = runCelc("table " + q(d / "sample") + " \"" + odd.string() + "\" --max-sigma 30 --plot " + q(d / "s.png"), d,
              true);
  ASSERT_EQ(r.status, 0) << r.err;
  expectPng(d / "s.png");
  fs::remove_all(d);
}

TEST(Plots, BatchPlotsEachRunAndTheTable) {
  REQUIRE_MATPLOTLIB();
  const fs::path d = celc::test::freshTempDir("plots_batch");
  std::ofstream(d / "batch.yaml") << "sequences:\n"
                                  << "  - {label: a, path: '" << kSample << "', t_end: 0.12}\n"
                                  << "  - {label: b, path: '" << kSample << "', t_end: 0.12, "
                                  << "config: {windows: {events: 40000}}}\n";
  const auto r = runCelc("batch " + q(d / "batch.yaml") + " -o " + q(d / "out") +
                             " -q --threads 2 --window-events 50000",
                         d, true);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warn"), std::string::npos) << r.err;
  for (const char* run : {"a", "b"}) {
    expectPng(d / "out" / run / "velocity.png");
    expectPng(d / "out" / run / "error.png");
  }
  expectPng(d / "out" / "table.png");
  fs::remove_all(d);
}
