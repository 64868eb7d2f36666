// `celc run` on a `celc synth` sequence measures its clusters against the
// true edges (labels.txt) and solves each window on its true clusters too
// (the oracle), in windows.csv's truth columns and the summary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "celc/eval/run_tables.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace celc {
namespace {

// The bundled sample (a rendered room, 2 windows): its clusters are nearly
// pure (the chessboards' edges run into each other at corners, so a few
// percent of a cluster may be another edge's). On the true clusters celc_ml
// is within 0.05 rad of the truth, the end-to-end tolerance of the rendered
// scenes (measured 0.007 and 0.033 rad: the seeded event draws of a window
// move it by a few hundredths), and the pipeline's celc_ml is within the
// oracle gap the summary counts, max(1.5x, +1 deg).
TEST(RunTruth, SampleWindowsCarryClusterQualityAndTheOracle) {
  const fs::path d = test::freshTempDir("run_truth");
  const auto r = test::runCelc("run '" CELC_SOURCE_DIR "/data/sample_seq' -q --no-plots -o '" + (d / "run").string() + "'", d);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = readWindowsCsv((d / "run" / "windows.csv").string(), false);
  ASSERT_FALSE(rows.empty());
  int ml = 0;
  for (const WindowsCsvRow& row : rows) {
    ASSERT_TRUE(row.has_truth) << "window " << row.window;
    EXPECT_GT(row.purity, 0.9) << "window " << row.window;
    EXPECT_LE(row.purity, 1.0);
    EXPECT_GT(row.edges, 5);
    EXPECT_LE(row.edges_complete, row.edges);
    EXPECT_GT(row.coverage, 0.5);
    EXPECT_LE(row.coverage, 1.0);
    ASSERT_TRUE(std::isfinite(row.oracle_phi)) << "window " << row.window;
    EXPECT_LT(row.oracle_phi, 0.05) << "window " << row.window;
    if (row.method == "celc_ml" && row.has_metrics) {
      ++ml;
      EXPECT_LE(row.phi, std::max(1.5 * row.oracle_phi, row.oracle_phi + M_PI / 180.0)) << "window " << row.window;
    }
  }
  EXPECT_EQ(ml, 2);
  const std::string summary = test::readAll(d / "run" / "summary.md");
  EXPECT_NE(summary.find("Clusters against the truth labels (2 windows"), std::string::npos) << summary;
  EXPECT_NE(summary.find("the oracle): 2 of 2 windows"), std::string::npos) << summary;
  // --truth-labels none: the truth columns stay empty.
  const auto off = test::runCelc("run '" CELC_SOURCE_DIR "/data/sample_seq' -q --no-plots --truth-labels none -o '" +
                                     (d / "off").string() + "'",
                                 d);
  ASSERT_EQ(off.status, 0) << off.err;
  for (const WindowsCsvRow& row : readWindowsCsv((d / "off" / "windows.csv").string(), false))
    EXPECT_FALSE(row.has_truth);
  // A labels file that does not match the events: one line naming both files.
  std::ofstream(d / "labels.txt") << "0\n1\n";
  const auto bad = test::runCelc("run '" CELC_SOURCE_DIR "/data/sample_seq' -q --no-plots --truth-labels '" +
                                     (d / "labels.txt").string() + "' -o '" + (d / "bad").string() + "'",
                                 d);
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("labels.txt: 2 labels for more than"), std::string::npos) << bad.err;
  fs::remove_all(d);
}

}  // namespace
}  // namespace celc
