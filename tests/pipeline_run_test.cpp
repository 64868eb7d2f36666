// celc run / batch / table end to end on the bundled simulated sequence.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "celc/config/config.hpp"
#include "celc/eval/run_tables.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/run_output.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace celc;
using celc::test::readAll;

namespace {
const std::string kSample = CELC_SOURCE_DIR "/data/sample_seq";

// A windows.csv line without its runtime_ms column (the 16th; quality columns follow).
std::string withoutRuntime(const std::string& l) {
  std::size_t pos = 0;
  for (int i = 0; i < 15 && pos != std::string::npos; ++i) pos = l.find(',', pos + 1);
  if (pos == std::string::npos) return l.substr(0, l.rfind(','));
  const std::size_t end = l.find(',', pos + 1);
  return l.substr(0, pos) + (end == std::string::npos ? std::string() : l.substr(end));
}

// Small windows over the first 0.12 s keep every run here to about a second.
const std::string kFast = " -q --threads 2 --window-events 15000 --set windows.t_end=0.12 ";
// The share of the sample's events in a cluster with kFast's windows is
// 86.6%; most of the rest lie in regions smaller than min_cluster_size.
constexpr double kMinClusteredPercent = 75.0;
}  // namespace

TEST(RunConfig, ShippedFileEqualsDefaults) {
  const RunConfig loaded = loadRunConfig(CELC_SOURCE_DIR "/config/run.yaml");
  EXPECT_EQ(toYaml(loaded), toYaml(RunConfig{}));
}

TEST(RunConfig, EffectiveConfigRoundTripsAndErrorsNameTheKey) {
  RunConfig c;
  applyRunConfig("windows: {policy: events, events: 1234}\ncluster: {smoothness_deg: 12}\nmethods: [celc]\n", "a.yaml", c);
  EXPECT_EQ(c.windows.events_per_window, 1234u);
  EXPECT_EQ(c.cluster.smoothness_deg, 12.0);
  RunConfig back;
  applyRunConfig(toYaml(c), "effective", back);
  EXPECT_EQ(toYaml(back), toYaml(c));
  try {
    RunConfig d;
    applyRunConfig("windows:\n  event: 10\n", "bad.yaml", d);
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("windows.event"), std::string::npos) << e.what();
  }
  RunConfig d;
  EXPECT_THROW(applyRunConfig("motion: {model: wobbly}\n", "m.yaml", d), std::exception);
  EXPECT_THROW(applyRunConfig("windows: {events: many}\n", "w.yaml", d), std::exception);
  EXPECT_THROW(applyRunConfig("cluster: {smoothnes_deg: 3}\n", "c.yaml", d), std::exception);
}

// The whole pipeline on the simulated room: every window and method has a
// row, the ground truth the pipeline computes from the pose file equals the
// simulator's twist, and the outputs exist.
TEST(Pipeline, RunOnBundledSampleWritesRowsAndGroundTruth) {
  const fs::path d = test::freshTempDir("pipe_run");
  const auto r = test::runCelc("run '" + kSample + "' -o '" + (d / "o").string() + "'" + kFast, d);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = readWindowsCsv((d / "o" / "windows.csv").string(), false);
  const size_t n_methods = RunConfig{}.methods.size();
  ASSERT_GE(rows.size(), n_methods * 3);  // >= 3 windows x every method
  std::map<std::int64_t, int> per_window;
  const Vec3 twist = Vec3(1.6, -0.3, 1.2).normalized();  // data/README.md
  for (const auto& row : rows) {
    per_window[row.window]++;
    EXPECT_FALSE(row.status.empty());
    ASSERT_TRUE(row.has_gt) << "window " << row.window;
    // Constant twist: the body-frame velocity direction is the same at all times.
    EXPECT_LT((row.gt - twist).norm(), 1e-3) << "window " << row.window;
    if (row.status == "ok") {
      EXPECT_TRUE(row.has_v);
      EXPECT_NEAR(row.v.norm(), 1.0, 1e-6);
      EXPECT_TRUE(row.has_metrics);
    }
  }
  for (const auto& [w, n] : per_window) EXPECT_EQ(n, static_cast<int>(n_methods)) << "window " << w;
  EXPECT_TRUE(fs::exists(d / "o" / "summary.md"));
  const std::string summary = readAll(d / "o" / "summary.md");
  EXPECT_NE(summary.find("| celc_opt |"), std::string::npos);
  // Where the events went: the clustered share and the ones left out add up
  // to 100% (each printed to 3 digits).
  const std::size_t at = summary.find("events in a cluster: ");
  ASSERT_NE(at, std::string::npos) << summary;
  const std::string line = summary.substr(at, summary.find('\n', at) - at);
  const std::regex share(R"(([0-9.e+-]+)% )");
  double total = 0.0, clustered = NAN;
  for (auto it = std::sregex_iterator(line.begin(), line.end(), share); it != std::sregex_iterator(); ++it) {
    const double x = std::stod((*it)[1].str());
    if (std::isnan(clustered)) clustered = x;
    total += x;
  }
  EXPECT_NEAR(total, 100.0, 0.5) << line;
  EXPECT_GT(clustered, kMinClusteredPercent) << line;
  EXPECT_NE(readAll(d / "o" / "config.yaml").find("events: 15000"), std::string::npos);
  EXPECT_NE(r.out.find("| celc |"), std::string::npos);
  // An existing output folder is refused without --force / --resume.
  const auto again = test::runCelc("run '" + kSample + "' -o '" + (d / "o").string() + "'" + kFast, d);
  EXPECT_NE(again.status, 0);
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
  fs::remove_all(d);
}

// Shards: the union of the N shares equals the single run, row for row, and
// `celc table` merges the shares into the same table.
TEST(Pipeline, ShardsUnionEqualsSingleRun) {
  const fs::path d = test::freshTempDir("pipe_shard");
  ASSERT_EQ(test::runCelc("run '" + kSample + "' -o '" + (d / "all" / "seq").string() + "'" + kFast, d).status, 0);
  for (int k = 1; k <= 2; ++k)
    ASSERT_EQ(test::runCelc("run '" + kSample + "' -o '" + (d / ("s" + std::to_string(k)) / "seq").string() +
                          "' --shard " + std::to_string(k) + "/2" + kFast, d).status, 0);
  auto lines = [](const fs::path& p) {
    std::multiset<std::string> s;
    std::stringstream ss(readAll(p));
    std::string l;
    std::getline(ss, l);
    while (std::getline(ss, l)) {
      // Drop runtime_ms: timing differs between runs.
      s.insert(withoutRuntime(l));
    }
    return s;
  };
  auto all = lines(d / "all" / "seq" / "windows.csv");
  auto s1 = lines(d / "s1" / "seq" / "windows.csv"), s2 = lines(d / "s2" / "seq" / "windows.csv");
  EXPECT_FALSE(s1.empty());
  EXPECT_FALSE(s2.empty());
  std::multiset<std::string> both = s1;
  both.insert(s2.begin(), s2.end());
  EXPECT_EQ(both, all);
  const auto t_single = test::runCelc("table '" + (d / "all").string() + "'", d);
  const auto t_merged = test::runCelc("table '" + (d / "s1").string() + "' '" + (d / "s2").string() + "'", d);
  ASSERT_EQ(t_single.status, 0) << t_single.err;
  EXPECT_EQ(t_single.out, t_merged.out);
  EXPECT_NE(t_single.out.find("| seq | eps (unit-vector distance) |"), std::string::npos) << t_single.out;
  EXPECT_NE(t_single.out.find("**"), std::string::npos);  // best in bold
  // --methods: the paper's three columns, in the order given; a method the
  // results do not hold, or no method at all, is an error.
  const auto paper = test::runCelc("table '" + (d / "all").string() + "' --methods celc,celc_opt,ce3lc", d);
  ASSERT_EQ(paper.status, 0) << paper.err;
  EXPECT_EQ(paper.out.substr(0, paper.out.find('\n')), "| sequence | error | CELC | CELC+opt | CE3LC |");
  const auto reordered = test::runCelc("table '" + (d / "all").string() + "' --methods ce3lc,celc", d);
  EXPECT_EQ(reordered.out.substr(0, reordered.out.find('\n')), "| sequence | error | CE3LC | CELC |");
  // -o DIR/prefix makes DIR, as `celc run -o` makes its folder.
  ASSERT_EQ(test::runCelc("table '" + (d / "all").string() + "' -q -o '" + (d / "new" / "dir" / "t").string() + "'", d)
                .status,
            0);
  EXPECT_TRUE(fs::exists(d / "new" / "dir" / "t.md"));
  const auto unknown = test::runCelc("table '" + (d / "all").string() + "' --methods celc,fast", d);
  EXPECT_NE(unknown.status, 0);
  EXPECT_NE(unknown.err.find("--methods 'celc,fast'"), std::string::npos) << unknown.err;
  EXPECT_EQ(t_merged.err.find("rows missing"), std::string::npos) << t_merged.err;
  // A shard that lost a row (cut or edited) is flagged: its methods would
  // be summarised over different windows.
  {
    const fs::path csv = d / "s2" / "seq" / "windows.csv";
    std::string text = readAll(csv);
    text.erase(text.find_last_of('\n', text.size() - 2) + 1);  // drop the last row
    std::ofstream(csv, std::ios::trunc) << text;
  }
  const auto t_cut = test::runCelc("table '" + (d / "s1").string() + "' '" + (d / "s2").string() + "'", d);
  ASSERT_EQ(t_cut.status, 0) << t_cut.err;
  EXPECT_NE(t_cut.err.find("'seq': 1 (window, method) rows missing"), std::string::npos) << t_cut.err;
  fs::remove_all(d);
}

// An interrupted run (windows.csv cut inside a window) resumes after its last
// complete window and ends with the same rows as an uninterrupted one.
TEST(Pipeline, ResumeAfterInterruptionLosesNothing) {
  const fs::path d = test::freshTempDir("pipe_resume");
  ASSERT_EQ(test::runCelc("run '" + kSample + "' -o '" + (d / "full").string() + "'" + kFast, d).status, 0);
  const std::string full = readAll(d / "full" / "windows.csv");
  // Keep the header, the first window and half a line of the second.
  const int n_methods = static_cast<int>(RunConfig{}.methods.size());
  std::stringstream ss(full);
  std::string l, cut;
  int line_no = 0;
  while (std::getline(ss, l)) {
    ++line_no;
    if (line_no <= 1 + n_methods) cut += l + "\n";
    else if (line_no == 2 + n_methods) cut += l.substr(0, l.size() / 2);
  }
  fs::create_directories(d / "part");
  std::ofstream(d / "part" / "windows.csv") << cut;
  fs::copy_file(d / "full" / "config.yaml", d / "part" / "config.yaml");  // resume checks it
  const auto r = test::runCelc("run '" + kSample + "' -o '" + (d / "part").string() + "' --resume" + kFast, d);
  ASSERT_EQ(r.status, 0) << r.err;
  auto strip = [](const std::string& text) {
    std::stringstream in(text);
    std::string line, out;
    while (std::getline(in, line)) out += withoutRuntime(line) + "\n";
    return out;
  };
  EXPECT_EQ(strip(readAll(d / "part" / "windows.csv")), strip(full));
  EXPECT_NE(readAll(d / "part" / "summary.md").find("resumed after window 0"), std::string::npos);
  fs::remove_all(d);
}

TEST(Pipeline, BadInputsGiveOneLineErrorsOrStatuses) {
  const fs::path d = test::freshTempDir("pipe_bad");
  // A directory without calibration.
  fs::create_directories(d / "seq");
  fs::copy_file(kSample + "/events.txt", d / "seq" / "events.txt");
  auto r = test::runCelc("run '" + (d / "seq").string() + "' -o '" + (d / "o1").string() + "'" + kFast, d);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("calibration"), std::string::npos) << r.err;
  // No IMU and no --omega: an error before the run, not windows of no_gyro.
  fs::copy_file(kSample + "/calib.yaml", d / "seq" / "calib.yaml");
  r = test::runCelc("run '" + (d / "seq").string() + "' -o '" + (d / "o2").string() + "'" + kFast, d);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("no IMU samples"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "o2"));
  // An IMU that stops early: the windows it does not cover get a status.
  {
    std::ifstream in(kSample + "/imu.txt");
    std::ofstream out(d / "seq" / "imu.txt");
    std::string line;
    for (int i = 0; i < 40 && std::getline(in, line); ++i) out << line << "\n";  // 40 ms
  }
  r = test::runCelc("run '" + (d / "seq").string() + "' -o '" + (d / "o3").string() + "'" + kFast, d);
  ASSERT_EQ(r.status, 0) << r.err;
  std::set<std::string> statuses;
  for (const auto& row : readWindowsCsv((d / "o3" / "windows.csv").string())) statuses.insert(row.status);
  EXPECT_TRUE(statuses.count("not_covered") || statuses.count("gyro_gap")) << *statuses.begin();
  // A wrong configuration key names the key and the file.
  std::ofstream(d / "bad.yaml") << "windows:\n  evnts: 3\n";
  r = test::runCelc("run '" + kSample + "' -c '" + (d / "bad.yaml").string() + "' -o '" + (d / "o4").string() + "'", d);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("bad.yaml:2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("windows.evnts"), std::string::npos) << r.err;
  // A missing input.
  r = test::runCelc("run '" + (d / "nothing").string() + "' -o '" + (d / "o5").string() + "'", d);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("nothing"), std::string::npos) << r.err;
  fs::remove_all(d);
}

TEST(Pipeline, BatchWritesPaperTables) {
  const fs::path d = test::freshTempDir("pipe_batch");
  std::ofstream(d / "batch.yaml") << "sequences:\n"
                                  << "  - {label: roomA, path: '" << kSample << "', t_end: 0.08}\n"
                                  << "  - {label: roomB, path: '" << kSample << "', t_end: 0.08, "
                                  << "config: {methods: [celc, ce3lc]}}\n";
  const auto r = test::runCelc("batch '" + (d / "batch.yaml").string() + "' -o '" + (d / "out").string() +
                             "' -q --window-events 15000",
                         d);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"table.md", "table.tex", "table.csv", "roomA/windows.csv", "roomB/summary.md"})
    EXPECT_TRUE(fs::exists(d / "out" / f)) << f;
  const std::string tex = readAll(d / "out" / "table.tex");
  EXPECT_NE(tex.find("\\toprule"), std::string::npos);
  EXPECT_NE(tex.find("\\textbf{"), std::string::npos);
  EXPECT_NE(readAll(d / "out" / "table.md").find("| roomB | phi [rad] |"), std::string::npos);
  // roomB ran only two methods.
  for (const auto& row : readWindowsCsv((d / "out" / "roomB" / "windows.csv").string()))
    EXPECT_TRUE(row.method == "celc" || row.method == "ce3lc") << row.method;
  std::ofstream(d / "bad.yaml") << "sequences:\n  - {label: x, pth: y}\n";
  const auto bad = test::runCelc("batch '" + (d / "bad.yaml").string() + "' -o '" + (d / "o2").string() + "'", d);
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("bad.yaml:2"), std::string::npos) << bad.err;
  fs::remove_all(d);
}
