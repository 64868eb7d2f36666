// The clusters against the truth (eval/cluster_quality.hpp): purity,
// completeness, coverage and noise admitted on hand-made labels whose values
// follow by counting; and the truth labels of a sequence (io/truth_labels.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "celc/eval/cluster_quality.hpp"
#include "celc/io/truth_labels.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace celc {
namespace {

// Edge 0: 100 events, 90 in cluster 0, 10 not clustered. Edge 1: 100 events,
// split 50 / 50 into clusters 1 and 2. Edge 2: 5 events in cluster 2 (too
// few to count as an edge of the window). 20 noise events, 5 in cluster 0.
void handMade(std::vector<int>& clusters, std::vector<int>& edges) {
  auto add = [&](int n, int cluster, int edge) {
    for (int i = 0; i < n; ++i) clusters.push_back(cluster), edges.push_back(edge);
  };
  add(90, 0, 0);
  add(10, -1, 0);
  add(50, 1, 1);
  add(50, 2, 1);
  add(5, 2, 2);
  add(5, 0, -1);
  add(15, -1, -1);
}

TEST(ClusterQualityMeasure, CountsOfHandMadeLabels) {
  std::vector<int> clusters, edges;
  handMade(clusters, edges);
  const ClusterQuality q = measureClusterQuality(clusters, edges);
  EXPECT_EQ(q.n_clusters, 3);
  EXPECT_EQ(q.n_clustered, 200u);
  // Majorities: 90 (cluster 0, against 5 noise), 50, 50 (against 5 of edge 2).
  EXPECT_DOUBLE_EQ(q.purity, 190.0 / 200.0);
  EXPECT_EQ(q.n_impure, 2);  // 90 / 95 and 50 / 55 are below 95%
  EXPECT_EQ(q.n_edges, 2);   // edge 2 has 5 < 20 events
  EXPECT_EQ(q.n_edges_complete, 1);
  EXPECT_EQ(q.n_edges_covered, 2);
  EXPECT_DOUBLE_EQ(q.completeness_median, 0.5 * (0.9 + 0.5));
  EXPECT_DOUBLE_EQ(q.coverage, 195.0 / 205.0);  // every edge event, edge 2's too
  EXPECT_DOUBLE_EQ(q.noise_admitted, 5.0 / 20.0);
}

TEST(ClusterQualityMeasure, PerfectClustersAndNothingClustered) {
  std::vector<int> edges(300);
  for (int i = 0; i < 300; ++i) edges[static_cast<std::size_t>(i)] = i / 100;
  const ClusterQuality perfect = measureClusterQuality(edges, edges);
  EXPECT_DOUBLE_EQ(perfect.purity, 1.0);
  EXPECT_EQ(perfect.n_impure, 0);
  EXPECT_EQ(perfect.n_edges_complete, 3);
  EXPECT_DOUBLE_EQ(perfect.coverage, 1.0);
  EXPECT_TRUE(std::isnan(perfect.noise_admitted));  // no noise events
  const ClusterQuality none = measureClusterQuality(std::vector<int>(300, -1), edges);
  EXPECT_TRUE(std::isnan(none.purity));
  EXPECT_EQ(none.n_clusters, 0);
  EXPECT_DOUBLE_EQ(none.coverage, 0.0);
  EXPECT_DOUBLE_EQ(none.completeness_median, 0.0);
  EXPECT_THROW(measureClusterQuality(std::vector<int>(3, 0), std::vector<int>(4, 0)), std::invalid_argument);
}

TEST(TruthLabelsFile, LooksUpEventsAndRefusesMisalignedFiles) {
  const fs::path d = test::freshTempDir("truth_labels");
  {
    std::ofstream ev(d / "events.txt"), lab(d / "labels.txt");
    for (int i = 0; i < 50; ++i) {
      ev << 0.25 * (i / 2) << " " << 10 + i << " " << 20 << " " << i % 2 << "\n";  // pairs share a time
      lab << (i % 5 == 0 ? -1 : i % 3) << "\n";
    }
  }
  const TruthLabels truth = TruthLabels::read((d / "events.txt").string(), (d / "labels.txt").string(), {});
  ASSERT_EQ(truth.size(), 50u);
  // Events as the reader gives them, in another order, and one that is not in the file.
  // Times are multiples of 0.25 s, exact in text and in binary.
  const std::vector<Event> window{{0.25 * 11, 33.0f, 20.0f, true}, {0.25 * 11, 32.0f, 20.0f, false},
                                  {0.0, 11.0f, 20.0f, true}, {0.5, 1.0f, 1.0f, true}};
  const std::vector<int> labels = truth.lookup(window);
  EXPECT_EQ(labels, (std::vector<int>{23 % 3, 22 % 3, 1 % 3, -1}));

  std::ofstream(d / "short.txt") << "1\n2\n";
  try {
    TruthLabels::read((d / "events.txt").string(), (d / "short.txt").string(), {});
    ADD_FAILURE() << "no error for 2 labels of 50 events";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("short.txt: 2 labels for more than"), std::string::npos) << what;
    EXPECT_NE(what.find("events.txt"), std::string::npos) << what;
  }
  std::ofstream(d / "bad.txt") << "1\nx7\n";
  try {
    TruthLabels::read((d / "events.txt").string(), (d / "bad.txt").string(), {});
    ADD_FAILURE() << "no error for a non-integer label";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt: line 2: expected an edge id"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}

}  // namespace
}  // namespace celc
