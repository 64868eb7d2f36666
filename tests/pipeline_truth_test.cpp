// `celc run` on a `celc synth` sequence measures its clusters against the
// true edges (labels.txt) and solves each window on its true clusters too
// (the oracle), in windows.csv's truth columns and the summary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

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


// The two scripts that read a run against the truth, on the bundled sample:
// cluster_quality.py --scenes counts the edges of one polarity over the
// windows' own edges; cluster_variants.py solves each dumped window again by
// its `celc solve` command, so its "pipeline" column is the run's phi (the
// dump's contract) and its "true_all" column, celc_ml on the true edges with
// the same seed, is the oracle's phi (0.5 deg allowed: the script finds an
// event's label by its pixel and microsecond, the run by its index). With
// --per-edge it also solves each edge of several clusters with only those
// joined: the sample has such edges, and like every labelling there they
// stay within a few degrees.
TEST(RunTruth, ScriptsReadTheRunAgainstTheTruth) {
  const fs::path d = test::freshTempDir("run_truth_scripts");
  const fs::path run = d / "sample_seq";
  const auto r = test::runCelc("run '" CELC_SOURCE_DIR "/data/sample_seq' -q --no-plots -o '" + run.string() +
                                   "' --dump-windows '" + (run / "windows").string() + "'",
                               d);
  ASSERT_EQ(r.status, 0) << r.err;
  std::map<int, WindowsCsvRow> ml;
  int edges = 0;
  for (const WindowsCsvRow& row : readWindowsCsv((run / "windows.csv").string(), false))
    if (row.method == "celc_ml") ml[row.window] = row, edges += row.edges;
  ASSERT_EQ(ml.size(), 2u);

  const auto quality = test::runShell("/usr/bin/python3 '" CELC_SOURCE_DIR "/scripts/cluster_quality.py' '" + d.string() +
                             "' --scenes '" CELC_SOURCE_DIR "/data'");
  ASSERT_EQ(quality.status, 0) << quality.out;
  const auto at = quality.out.find("of their events of one polarity");
  ASSERT_NE(at, std::string::npos) << quality.out;
  const std::string line = quality.out.substr(at, quality.out.find('\n', at) - at);
  int one = -1, counted = -1;
  ASSERT_EQ(std::sscanf(line.substr(line.find('(', line.find("| ")) + 1).c_str(), "%d / %d", &one, &counted), 2)
      << line;
  EXPECT_EQ(counted, edges) << line;
  EXPECT_GE(one, 0);
  EXPECT_LE(one, counted);

  const auto variants = test::runShell("/usr/bin/python3 '" CELC_SOURCE_DIR "/scripts/cluster_variants.py' '" + run.string() +
                              "' '" CELC_SOURCE_DIR "/data/sample_seq' --per-edge");
  ASSERT_EQ(variants.status, 0) << variants.out;
  std::istringstream lines(variants.out);
  std::string row_text;
  int rows = 0;
  while (std::getline(lines, row_text)) {
    int w;
    double run_phi, oracle, pipeline, pure, joined, true_kept, completed, true_found, true_all, kept;
    if (std::sscanf(row_text.c_str(), "| %d | %lf | %lf | %lf | %lf | %lf | %lf | %lf | %lf | %lf | %lf |", &w,
                    &run_phi, &oracle, &pipeline, &pure, &joined, &true_kept, &completed, &true_found, &true_all,
                    &kept) != 11)
      continue;
    ++rows;
    ASSERT_EQ(ml.count(w), 1u) << row_text;
    const double deg = 180.0 / M_PI;
    EXPECT_NEAR(run_phi, ml[w].phi * deg, 0.01) << row_text;
    EXPECT_NEAR(oracle, ml[w].oracle_phi * deg, 0.01) << row_text;
    EXPECT_NEAR(pipeline, run_phi, 0.02) << row_text;
    EXPECT_NEAR(true_all, oracle, 0.5) << row_text;
    // The sample's clusters are nearly pure and whole: each labelling is a few degrees at most.
    for (double phi : {pure, joined, true_kept, completed, true_found}) EXPECT_LT(phi, 5.0) << row_text;
    EXPECT_NEAR(kept, ml[w].coverage, 0.02) << row_text;
  }
  EXPECT_EQ(rows, 2) << variants.out;
  EXPECT_NE(variants.out.find("Windows where the pipeline's clusters are beyond the oracle gap: 0"),
            std::string::npos)
      << variants.out;
  // The per-edge table: | window | edge | its clusters | its events in them | phi [deg] | within the gap |
  const std::size_t edge_table = variants.out.find("One edge's clusters joined");
  ASSERT_NE(edge_table, std::string::npos) << variants.out;
  std::istringstream edge_lines(variants.out.substr(edge_table));
  int edge_rows = 0;
  while (std::getline(edge_lines, row_text)) {
    int w, edge, clusters, events_in;
    double phi;
    char within[4] = {};
    if (std::sscanf(row_text.c_str(), "| %d | %d | %d | %d | %lf | %3s |", &w, &edge, &clusters, &events_in, &phi,
                    within) != 6)
      continue;
    ++edge_rows;
    EXPECT_EQ(ml.count(w), 1u) << row_text;
    EXPECT_GE(clusters, 2) << row_text;
    EXPECT_GT(events_in, 0) << row_text;
    EXPECT_LT(phi, 5.0) << row_text;
  }
  EXPECT_GE(edge_rows, 1) << variants.out;
  EXPECT_NE(variants.out.find("Edges with several clusters: " + std::to_string(edge_rows) + ";"), std::string::npos)
      << variants.out;

  // Where the foreign events come from: the shares add up to the run's own
  // purity, and the sample's edges are parallel stripes, so its foreign edge
  // events are of a parallel neighbour (none at a corner, none crossing).
  const auto sources = test::runShell("/usr/bin/python3 '" CELC_SOURCE_DIR "/scripts/impurity_sources.py' '" +
                                      run.string() + "' '" CELC_SOURCE_DIR "/data/sample_seq'");
  ASSERT_EQ(sources.status, 0) << sources.out;
  std::istringstream source_lines(sources.out);
  int source_rows = 0;
  while (std::getline(source_lines, row_text)) {
    int w, clustered;
    double purity, noise, foreign, corner, crossing, parallel;
    if (std::sscanf(row_text.c_str(), "| %d | %d | %lf | %lf | %lf | %lf | %lf | %lf |", &w, &clustered, &purity,
                    &noise, &foreign, &corner, &crossing, &parallel) != 8)
      continue;
    ++source_rows;
    ASSERT_EQ(ml.count(w), 1u) << row_text;
    EXPECT_GT(clustered, 0) << row_text;
    EXPECT_NEAR(purity, ml[w].purity, 0.0006) << row_text;  // both rounded to 3 and 4 decimals
    EXPECT_NEAR(noise + foreign, 1.0 - purity, 0.0016) << row_text;
    EXPECT_NEAR(corner + crossing + parallel, foreign, 0.0016) << row_text;
    EXPECT_GT(foreign, 0.0) << row_text;
    EXPECT_EQ(corner, 0.0) << row_text;
    EXPECT_EQ(crossing, 0.0) << row_text;
  }
  EXPECT_EQ(source_rows, 2) << sources.out;
  fs::remove_all(d);
}

}  // namespace
}  // namespace celc
