// `celc run` / `celc table` refuse what would give silent mis-runs, resume
// only the same configuration, name their rows, and never take a failed or
// interrupted run for a result. Each case:
// the exit status and the one-line message.
#include <gtest/gtest.h>

#include <functional>
#include <sstream>

#include <filesystem>
#include <fstream>
#include <string>

#include "celc/eval/run_tables.hpp"
#include "celc/pipeline/run_config.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace celc;
using celc::test::readAll;
using celc::test::runCelc;

namespace {
const std::string kSample = CELC_SOURCE_DIR "/data/sample_seq";
// The first 0.12 s (89,512 events) keep each run to about a second.
const std::string kFast = " -q --threads 2 --set windows.t_end=0.12 ";

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

// One line on stderr holding every fragment.
void expectOneLineError(const test::CliRun& r, std::initializer_list<std::string> fragments) {
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_EQ(r.err.rfind("celc: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << "'" << f << "' not in " << r.err;
}

// A sequence folder from the sample: its calibration and IMU, and its events
// with each line (numbered from 1) as `edit(no, line)` returns it.
fs::path sequenceWithEditedEvents(const fs::path& dir,
                                  const std::function<std::string(int, const std::string&)>& edit) {
  fs::create_directories(dir);
  for (const char* f : {"calib.yaml", "imu.txt"})
    fs::copy_file(kSample + "/" + f, dir / f, fs::copy_options::overwrite_existing);
  std::ifstream in(kSample + "/events.txt");
  std::ofstream out(dir / "events.txt");
  std::string line;
  for (int no = 1; std::getline(in, line); ++no) out << edit(no, line) << "\n";
  return dir;
}

// ... with a line that is not an event inserted before line `bad_line` (0: none).
fs::path sequenceWithBadLine(const fs::path& dir, int bad_line) {
  return sequenceWithEditedEvents(
      dir, [&](int no, const std::string& line) { return no == bad_line ? "not an event\n" + line : line; });
}
}  // namespace

// ---- no silent mis-runs ----

TEST(CliTrust, WindowSizesMustBePositiveAndFinite) {
  const fs::path d = test::freshTempDir("trust_win");
  const std::string run = "run '" + kSample + "' -o " + q(d / "o") + kFast;
  expectOneLineError(runCelc(run + "--window-events 0", d), {"--window-events '0'", "positive"});
  for (const char* s : {"-0.1", "0", "nan", "inf"})
    expectOneLineError(runCelc(run + "--window-seconds " + s, d), {"--window-seconds '" + std::string(s) + "'"});
  expectOneLineError(runCelc(run + "--window-events 100 --window-seconds 0.1", d), {"--window-events", "not both"});
  // The same through the configuration: the key is named.
  expectOneLineError(runCelc(run + "--set windows.seconds=-0.1", d), {"windows.seconds", "> 0"});
  expectOneLineError(runCelc(run + "--set windows.seconds=0.1", d), {"windows.policy", "parallax"});
  expectOneLineError(runCelc(run + "--set windows.overlap=1", d), {"windows.overlap", "[0, 1)"});
  expectOneLineError(runCelc(run + "--set windows.overlap=-0.5", d), {"windows.overlap"});
  EXPECT_FALSE(fs::exists(d / "o"));
  fs::remove_all(d);
}

TEST(CliTrust, ThreadCountsAreChecked) {
  const fs::path d = test::freshTempDir("trust_threads");
  const std::string run = "run '" + kSample + "' -o " + q(d / "o") + " -q --set windows.t_end=0.12 ";
  expectOneLineError(runCelc(run + "--threads -1", d), {"--threads -1"});
  expectOneLineError(runCelc(run + "--threads 100000", d), {"--threads 100000"});
  expectOneLineError(runCelc(run + "--set cluster.threads=0", d), {"threads"});
  EXPECT_FALSE(fs::exists(d / "o"));
  const std::string simulate = "simulate --sweep default --trials 2 -q -o " + q(d / "s") + " ";
  expectOneLineError(runCelc(simulate + "--threads -1", d), {"--threads"});
  expectOneLineError(runCelc(simulate + "--threads 100000", d), {"--threads"});
  EXPECT_FALSE(fs::exists(d / "s"));
  fs::remove_all(d);
}

TEST(CliTrust, WindowRateIsBounded) {
  const fs::path d = test::freshTempDir("trust_rate");
  const std::string run = "run '" + kSample + "' -o " + q(d / "o") + kFast;
  // By duration: known before reading.
  expectOneLineError(runCelc(run + "--window-seconds 1e-9", d),
                     {"--window-seconds 1e-9", "windows per second", "windows.max_windows_per_second = 10000"});
  std::ofstream(d / "tiny.yaml") << "windows: {policy: seconds, events: 0, seconds: 1.0e-6}\n";
  expectOneLineError(runCelc("run '" + kSample + "' -c " + q(d / "tiny.yaml") + " -o " + q(d / "o") + kFast, d),
                     {"tiny.yaml", "windows.seconds", "max_windows_per_second"});
  // By count: from the event rate, before the first window is processed.
  expectOneLineError(runCelc(run + "--window-events 1", d), {"windows.events = 1", "max_windows_per_second"});
  EXPECT_FALSE(fs::exists(d / "o"));
  // The bound is an option: raised, the same policy runs.
  const auto ok = runCelc(run + "--window-seconds 0.05 --set windows.max_windows_per_second=20", d);
  EXPECT_EQ(ok.status, 0) << ok.err;
  expectOneLineError(runCelc("run '" + kSample + "' -o " + q(d / "p") + kFast +
                                 "--window-seconds 0.05 --set windows.max_windows_per_second=19",
                             d),
                     {"windows per second", "max_windows_per_second = 19"});
  fs::remove_all(d);
}

TEST(CliTrust, CalibrationOfAnotherSensorSizeIsRefused) {
  const fs::path d = test::freshTempDir("trust_calib");
  // The sample's calibration is 346x260: a recording that states 240x180.
  std::ofstream(d / "davis240.yaml") << "input: {width: 240, height: 180}\n";
  expectOneLineError(runCelc("run '" + kSample + "' -c " + q(d / "davis240.yaml") + " -o " + q(d / "o") + kFast, d),
                     {"calib.yaml", "346x260", "240x180"});
  // A 100x80 calibration on the 346x260 recording.
  std::ofstream(d / "small.yaml") << "camera: {width: 100, height: 80, fx: 200, fy: 200, cx: 50, cy: 40}\n";
  std::ofstream(d / "davis346.yaml") << "input: {width: 346, height: 260}\n";
  expectOneLineError(runCelc("run '" + kSample + "' -c " + q(d / "davis346.yaml") + " --calib " + q(d / "small.yaml") +
                                 " -o " + q(d / "o") + kFast,
                             d),
                     {"small.yaml", "100x80", "346x260"});
  EXPECT_FALSE(fs::exists(d / "o"));
  fs::remove_all(d);
}

// Clusters whose lines cannot be fitted are counted in the summary and their
// reasons logged with --verbose.
TEST(CliTrust, ClustersWithoutLinesAreCountedAndExplained) {
  const fs::path d = test::freshTempDir("trust_lines");
  const auto r = runCelc("run '" + kSample + "' -o " + q(d / "o") +
                             " --window-events 50000 --set windows.t_end=0.12 --set lines.min_length_px=150 -v",
                         d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lines not fitted (l1 poor_fit"), std::string::npos) << r.err;
  EXPECT_NE(readAll(d / "o" / "summary.md").find("clusters whose start / end lines could not be fitted: used by npt only"),
            std::string::npos);
  fs::remove_all(d);
}

TEST(CliTrust, RecordingWithoutImuNeedsOmega) {
  const fs::path d = test::freshTempDir("trust_imu");
  fs::create_directories(d / "seq");
  for (const char* f : {"calib.yaml", "events.txt"}) fs::copy_file(kSample + "/" + f, d / "seq" / f);
  expectOneLineError(runCelc("run " + q(d / "seq") + " -o " + q(d / "o") + kFast + "--window-events 15000", d),
                     {"seq: no IMU samples", "--imu", "--omega"});
  EXPECT_FALSE(fs::exists(d / "o"));
  const auto r = runCelc("run " + q(d / "seq") + " -o " + q(d / "o") + kFast + "--window-events 15000 --omega 0,0,0", d);
  EXPECT_EQ(r.status, 0) << r.err;
  fs::remove_all(d);
}

TEST(CliTrust, LastPartialWindowProcessedFromHalfAWindowElseReported) {
  const fs::path d = test::freshTempDir("trust_partial");
  const size_t n_methods = RunConfig{}.methods.size();
  // 89,512 events in 15,000-event windows: 5 full windows and 14,512 events (97%).
  auto r = runCelc("run '" + kSample + "' -o " + q(d / "a") + kFast + "--window-events 15000", d);
  ASSERT_EQ(r.status, 0) << r.err;
  auto rows = readWindowsCsv((d / "a" / "windows.csv").string());
  ASSERT_EQ(rows.size(), 6 * n_methods);
  EXPECT_EQ(rows.back().n_events, 14512);
  EXPECT_NE(r.out.find("last, partial window: 14512 events, 96.7% of a window, processed"), std::string::npos) << r.out;
  // In 20,000-event windows: 4 full windows and 9,512 events (48%): reported, not processed.
  r = runCelc("run '" + kSample + "' -o " + q(d / "b") + kFast + "--window-events 20000", d);
  ASSERT_EQ(r.status, 0) << r.err;
  rows = readWindowsCsv((d / "b" / "windows.csv").string());
  EXPECT_EQ(rows.size(), 4 * n_methods);
  EXPECT_NE(readAll(d / "b" / "summary.md").find("last, partial window: 9512 events, 47.6% of a window, not processed"),
            std::string::npos);
  // The share is an option.
  r = runCelc("run '" + kSample + "' -o " + q(d / "c") + kFast + "--window-events 20000 --set windows.partial_min_share=0.4", d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readWindowsCsv((d / "c" / "windows.csv").string()).size(), 5 * n_methods);
  fs::remove_all(d);
}

// Events outside the sensor of a recording that states no size (text) are
// checked against the calibration's image (calib.yaml: 346x260): a few are
// counted and dropped, many stop the run with one line, never used silently.
TEST(CliTrust, PixelsOutsideTheCalibratedImageAreNotUsedSilently) {
  const fs::path d = test::freshTempDir("trust_outside");
  auto sequenceWithOutside = [&](const fs::path& dir, int every, int limit) {
    int moved = 0;
    return sequenceWithEditedEvents(dir, [&](int no, const std::string& line) {
      if (no % every != 0 || moved >= limit) return line;
      ++moved;
      std::istringstream fields(line);
      std::string t, x, y, p;
      fields >> t >> x >> y >> p;
      return t + " " + std::to_string(346 + no % 60000) + " " + y + " " + p;  // outside the 346 px wide image
    });
  };
  const fs::path many = sequenceWithOutside(d / "many", 7, 1 << 30), few = sequenceWithOutside(d / "few", 1000, 10);
  expectOneLineError(runCelc("run " + q(many) + " -o " + q(d / "o_many") + kFast + "--window-events 15000", d),
                     {"outside the 346x260 sensor", "input.max_outside_share"});
  const auto r = runCelc("run " + q(few) + " -o " + q(d / "o_few") + kFast + "--window-events 15000 -v", d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(readAll(d / "o_few" / "summary.md").find("reader warnings"), std::string::npos);
  fs::remove_all(d);
}

TEST(CliTrust, CalibTxtWithoutASizeIsNotTakenForTheSensorSilently) {
  // The 346x260 sample with only its calib.txt, which states no image size:
  // the 240x180 it assumes is said, and events beyond it are an error naming the options.
  const fs::path d = test::freshTempDir("trust_calibtxt");
  const fs::path seq = d / "seq";
  fs::create_directories(seq);
  for (const char* f : {"events.txt", "imu.txt", "calib.txt"}) fs::copy_file(kSample + "/" + f, seq / f);
  auto r = runCelc("run " + q(seq) + " -o " + q(d / "o") + kFast + "--window-events 15000", d);
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.err.find("neither it nor"), std::string::npos) << r.err;  // the warning, before the run
  const std::size_t error = r.err.find("celc: error: ");
  ASSERT_NE(error, std::string::npos) << r.err;
  const std::string line = r.err.substr(error);
  EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << r.err;
  for (const char* f : {"events.txt: line", "outside the 240x180 sensor", "input.width / input.height"})
    EXPECT_NE(line.find(f), std::string::npos) << "'" << f << "' not in " << line;
  r = runCelc("run " + q(seq) + " -o " + q(d / "o2") + kFast +
                  "--window-events 15000 --set input.width=346 --set input.height=260",
              d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("neither it nor"), std::string::npos) << r.err;
  const std::string summary = readAll(d / "o2" / "summary.md");
  EXPECT_NE(summary.find("calib.txt (346x260"), std::string::npos) << summary;
  fs::remove_all(d);
}

TEST(CliTrust, PathsInErrorsAreEscaped) {
  // A file name holding an ANSI escape: the message quotes it as \x1B, never raw.
  const fs::path d = test::freshTempDir("trust_escape");
  const fs::path bad = d / "e\x1b[31mred\x07.txt";
  { std::ofstream(bad) << std::string("\x01\x02binary", 8); }
  for (const std::string& cmd : {"info " + q(bad), "run " + q(bad) + " --calib " + q(kSample + "/calib.yaml") + " -o " + q(d / "o") + kFast,
                                 "info " + q(d / "missing\x1b[0m")}) {
    const auto r = runCelc(cmd, d);
    EXPECT_NE(r.status, 0) << cmd;
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << cmd << ": " << r.err;
    EXPECT_EQ(r.err.find('\x07'), std::string::npos) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("\\x1B["), std::string::npos) << cmd << ": " << r.err;
  }
  fs::remove_all(d);
}

// ---- resume that checks ----

TEST(CliTrust, ResumeRefusesAnotherConfigurationAndKeepsRows) {
  const fs::path d = test::freshTempDir("trust_resume");
  const std::string run = "run '" + kSample + "' -o " + q(d / "o") + kFast;
  ASSERT_EQ(runCelc(run + "--window-events 15000", d).status, 0);
  const std::string rows = readAll(d / "o" / "windows.csv"), config = readAll(d / "o" / "config.yaml");
  expectOneLineError(runCelc(run + "--window-events 20000 --resume", d),
                     {"config.yaml", "windows.events: 15000 vs 20000", "--resume"});
  expectOneLineError(runCelc(run + "--window-events 15000 --methods celc --resume", d), {"config.yaml", "methods:"});
  EXPECT_EQ(readAll(d / "o" / "windows.csv"), rows);  // nothing deleted
  EXPECT_EQ(readAll(d / "o" / "config.yaml"), config);  // nothing rewritten
  // Result-neutral options (threads) do not count.
  auto r = runCelc("run '" + kSample + "' -o " + q(d / "o") + " -q --threads 1 --set windows.t_end=0.12 "
                   "--window-events 15000 --resume", d);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readAll(d / "o" / "windows.csv"), rows);
  // --resume --force replaces a run of another configuration, and says so.
  r = runCelc(run + "--window-events 20000 --resume --force", d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("replaced the earlier run"), std::string::npos) << r.out;
  EXPECT_NE(readAll(d / "o" / "config.yaml").find("events: 20000"), std::string::npos);
  // Rows without their config.yaml cannot be checked.
  fs::remove(d / "o" / "config.yaml");
  expectOneLineError(runCelc(run + "--window-events 20000 --resume", d), {"config.yaml", "missing"});
  fs::remove_all(d);
}

// --resume continues the same recording only: rows of one sequence followed
// by another's would be one table of neither.
TEST(CliTrust, ResumeRefusesAnotherRecording) {
  const fs::path d = test::freshTempDir("trust_resume_input");
  fs::copy(kSample, d / "other", fs::copy_options::recursive);
  ASSERT_EQ(runCelc("run '" + kSample + "' -o " + q(d / "o") + kFast + "--window-events 15000", d).status, 0);
  const std::string rows = readAll(d / "o" / "windows.csv");
  EXPECT_NE(readAll(d / "o" / "input.txt").find("sample_seq"), std::string::npos);
  expectOneLineError(runCelc("run " + q(d / "other") + " -o " + q(d / "o") + kFast + "--window-events 15000 --resume", d),
                     {"input.txt: holds a run of other inputs", "--resume continues the same recording only"});
  EXPECT_EQ(readAll(d / "o" / "windows.csv"), rows);  // nothing deleted
  // The same recording resumes.
  const auto same = runCelc("run '" + kSample + "' -o " + q(d / "o") + kFast + "--window-events 15000 --resume", d);
  EXPECT_EQ(same.status, 0) << same.err;
  fs::remove_all(d);
}

// ---- tables that name runs ----

TEST(CliTrust, TableKeepsRunsOfTheSameNameApart) {
  const fs::path d = test::freshTempDir("trust_table");
  ASSERT_EQ(runCelc("run '" + kSample + "' -o " + q(d / "a" / "sample") + kFast + "--window-events 15000", d).status, 0);
  ASSERT_EQ(runCelc("run '" + kSample + "' -o " + q(d / "b" / "sample") + kFast + "--window-events 20000", d).status, 0);
  auto r = runCelc("table " + q(d / "a") + " " + q(d / "b"), d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| a/sample | eps (unit-vector distance) |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| b/sample | phi [rad] |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("distance between the unit"), std::string::npos) << r.out;
  r = runCelc("table --label w15k=" + q(d / "a" / "sample") + " --label w20k=" + q(d / "b" / "sample") + " -o " +
                  q(d / "t"),
              d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| w15k | eps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| w20k | phi"), std::string::npos) << r.out;
  EXPECT_NE(readAll(d / "t.csv").find("\nw20k,celc,"), std::string::npos);
  expectOneLineError(runCelc("table --label nameonly", d), {"--label 'nameonly'", "NAME=PATH"});
  expectOneLineError(runCelc("table", d), {"--label NAME=PATH"});
  fs::remove_all(d);
}

TEST(CliTrust, BatchLabelsNameTheRows) {
  const fs::path d = test::freshTempDir("trust_batch");
  std::ofstream(d / "batch.yaml") << "sequences:\n"
                                  << "  - {label: fine, path: '" << kSample << "', t_end: 0.08}\n"
                                  << "  - {label: coarse, path: '" << kSample << "', t_end: 0.08, "
                                  << "config: {windows: {events: 20000}}}\n";
  auto r = runCelc("batch " + q(d / "batch.yaml") + " -o " + q(d / "out") + " -q --window-events 15000", d);
  ASSERT_EQ(r.status, 0) << r.err;
  r = runCelc("table " + q(d / "out"), d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| fine | eps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| coarse | eps"), std::string::npos) << r.out;
  fs::remove_all(d);
}

// ---- failed and interrupted runs are never results ----

TEST(CliTrust, RunFailingBeforeItsFirstWindowLeavesNothing) {
  const fs::path d = test::freshTempDir("trust_early");
  const fs::path seq = sequenceWithBadLine(d / "seq", 10);
  expectOneLineError(runCelc("run " + q(seq) + " -o " + q(d / "o") + kFast + "--window-events 15000", d),
                     {"events.txt", "line 10"});
  EXPECT_FALSE(fs::exists(d / "o"));
  // An existing, empty folder stays (empty).
  fs::create_directories(d / "e");
  EXPECT_NE(runCelc("run " + q(seq) + " -o " + q(d / "e") + kFast + "--window-events 15000", d).status, 0);
  EXPECT_TRUE(fs::exists(d / "e"));
  EXPECT_TRUE(fs::is_empty(d / "e"));
  // A header-only windows.csv (a run killed before its first window) is not a run: no --force needed.
  fs::create_directories(d / "h");
  std::ofstream(d / "h" / "windows.csv") << windowsCsvHeader() << "\n";
  std::ofstream(d / "h" / "INCOMPLETE") << "killed\n";
  const auto r = runCelc("run '" + kSample + "' -o " + q(d / "h") + kFast + "--window-events 15000", d);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(d / "h" / "INCOMPLETE"));
  fs::remove_all(d);
}

TEST(CliTrust, RunStoppingOnAnErrorIsMarkedAndTableRefusesIt) {
  const fs::path d = test::freshTempDir("trust_mid");
  const fs::path good = sequenceWithBadLine(d / "good", 0), bad = sequenceWithBadLine(d / "bad", 150000);
  const std::string opts = " -q --threads 2 --window-events 15000 ";
  // A complete run: no marker.
  ASSERT_EQ(runCelc("run " + q(good) + " -o " + q(d / "r" / "seq") + opts, d).status, 0);
  EXPECT_FALSE(fs::exists(d / "r" / "seq" / "INCOMPLETE"));
  EXPECT_TRUE(fs::exists(d / "r" / "seq" / "summary.md"));
  // --force on a recording that fails mid-file: the old summary is gone first,
  // the finished windows stay, and the folder is marked.
  expectOneLineError(runCelc("run " + q(bad) + " -o " + q(d / "r" / "seq") + opts + "--force", d),
                     {"events.txt", "line 150000"});
  EXPECT_FALSE(fs::exists(d / "r" / "seq" / "summary.md"));
  ASSERT_TRUE(fs::exists(d / "r" / "seq" / "INCOMPLETE"));
  EXPECT_NE(readAll(d / "r" / "seq" / "INCOMPLETE").find("line 150000"), std::string::npos);
  EXPECT_GT(readWindowsCsv((d / "r" / "seq" / "windows.csv").string()).size(), 0u);
  // celc table refuses the folder (given directly or inside a batch-like folder) ...
  expectOneLineError(runCelc("table " + q(d / "r" / "seq"), d), {"INCOMPLETE", "incomplete run", "--allow-incomplete"});
  expectOneLineError(runCelc("table " + q(d / "r"), d), {"INCOMPLETE"});
  expectOneLineError(runCelc("table " + q(d / "r" / "seq" / "windows.csv"), d), {"INCOMPLETE"});
  // ... or flags it when asked.
  auto r = runCelc("table --allow-incomplete " + q(d / "r"), d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| seq (incomplete) | eps"), std::string::npos) << r.out;
  // A new run without --force/--resume is refused; once the file is repaired
  // in place, --resume completes it and removes the marker.
  expectOneLineError(runCelc("run " + q(bad) + " -o " + q(d / "r" / "seq") + opts, d), {"--force", "--resume"});
  fs::copy_file(good / "events.txt", bad / "events.txt", fs::copy_options::overwrite_existing);
  r = runCelc("run " + q(bad) + " -o " + q(d / "r" / "seq") + opts + "--resume", d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(d / "r" / "seq" / "INCOMPLETE"));
  EXPECT_EQ(runCelc("table " + q(d / "r"), d).status, 0);
  fs::remove_all(d);
}
