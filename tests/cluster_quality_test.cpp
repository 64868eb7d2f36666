// Clustering quality on labelled synthetic windows, and degenerate windows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "celc/cluster/cluster.hpp"
#include "celc/cluster/synthetic.hpp"

namespace celc {
namespace {

struct Score {
  int lines = 0, recovered = 0;
  int noise = 0, noise_clustered = 0;
  int line_events = 0, line_events_clustered = 0;
};

// A true line is recovered when one cluster holds >= 80% of its events with purity >= 0.9.
Score score(const LabelledWindow& w, const ClusterResult& r) {
  Score s;
  s.lines = w.n_lines();
  std::vector<int> cluster_size(r.clusters.size(), 0);
  std::map<std::pair<int, int>, int> joint;  // (line, cluster) -> events
  std::vector<int> line_size(w.n_lines(), 0);
  for (size_t i = 0; i < w.events.size(); ++i) {
    const int c = r.labels[i], l = w.labels[i];
    if (c >= 0) ++cluster_size[c];
    if (l < 0) {
      ++s.noise;
      if (c >= 0) ++s.noise_clustered;
      continue;
    }
    ++line_size[l];
    ++s.line_events;
    if (c >= 0) ++joint[{l, c}], ++s.line_events_clustered;
  }
  for (int l = 0; l < w.n_lines(); ++l) {
    bool ok = false;
    for (const auto& [key, n] : joint)
      if (key.first == l && n >= 0.8 * line_size[l] && n >= 0.9 * cluster_size[key.second]) ok = true;
    s.recovered += ok ? 1 : 0;
  }
  return s;
}

TEST(ClusterQuality, ProbeGrid) {
  const char* e = getenv("PROBE");
  if (!e) GTEST_SKIP();
  ClusterOptions co;
  sscanf(e, "%d %lf %lf %lf %lf %lf", &co.grid_radius_px, &co.time_radius_px, &co.smoothness_deg, &co.curvature_threshold, &co.max_plane_rms_px, &co.grow_time_radius_px);
  if (getenv("PCL")) co.method = ClusterMethod::Pcl;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    LabelledWindowOptions wo;
    wo.seed = seed;
    const LabelledWindow w = generateLabelledWindow(wo);
    const ClusterResult r = clusterEvents(w.events, co);
    const Score s = score(w, r);
    printf("seed %u: c=%.1f clusters=%zu rec=%d/%d noise %d/%d line ev %d/%d split %d rejp %d regions %d ms %.1f (c %.1f grow %.1f post %.1f)\n",
           seed, r.c_px_per_s, r.clusters.size(), s.recovered, s.lines, s.noise_clustered, s.noise,
           s.line_events_clustered, s.line_events, r.n_split, r.n_rejected_planar, r.n_regions, r.ms_total, r.ms_time_scale, r.ms_grow, r.ms_post);
  }
}

}  // namespace
}  // namespace celc
