#include "celc/eval/cluster_quality.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

namespace celc {

ClusterQuality measureClusterQuality(const std::vector<int>& clusters, const std::vector<int>& edges,
                                     const ClusterQualityOptions& options) {
  if (clusters.size() != edges.size())
    throw std::invalid_argument("measureClusterQuality: " + std::to_string(clusters.size()) + " cluster labels for " +
                                std::to_string(edges.size()) + " edge labels");
  ClusterQuality q;
  // Counts per (cluster, edge) and per edge; edge -1 is noise.
  std::map<int, std::map<int, std::size_t>> per_cluster;
  std::map<int, std::size_t> edge_events;
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    const int c = clusters[i], e = edges[i];
    if (e >= 0) ++edge_events[e];
    else ++q.n_noise_events;
    if (c < 0) continue;
    ++q.n_clustered;
    ++per_cluster[c][e];
  }
  std::size_t majority_total = 0, noise_clustered = 0, edge_clustered = 0;
  std::map<int, std::size_t> largest_share;  // per edge: its events in its largest cluster
  std::map<int, bool> is_majority;           // per edge: the majority edge of some cluster
  for (const auto& [c, counts] : per_cluster) {
    std::size_t total = 0, best = 0;
    int best_edge = -1;
    for (const auto& [e, n] : counts) {
      total += n;
      if (e < 0) {
        noise_clustered += n;
        continue;
      }
      edge_clustered += n;
      largest_share[e] = std::max(largest_share[e], n);
      if (n > best) best = n, best_edge = e;
    }
    majority_total += best;
    ++q.n_clusters;
    if (static_cast<double>(best) < options.pure_share * static_cast<double>(total)) ++q.n_impure;
    if (best_edge >= 0) is_majority[best_edge] = true;
  }
  std::vector<double> completeness;
  for (const auto& [e, n] : edge_events) {
    q.n_edge_events += n;
    if (n < options.min_edge_events) continue;
    ++q.n_edges;
    const double share = static_cast<double>(largest_share[e]) / static_cast<double>(n);
    completeness.push_back(share);
    if (share >= options.complete_share) ++q.n_edges_complete;
    if (is_majority[e]) ++q.n_edges_covered;
  }
  q.purity = q.n_clustered ? static_cast<double>(majority_total) / static_cast<double>(q.n_clustered) : NAN;
  q.coverage = q.n_edge_events ? static_cast<double>(edge_clustered) / static_cast<double>(q.n_edge_events) : NAN;
  q.noise_admitted =
      q.n_noise_events ? static_cast<double>(noise_clustered) / static_cast<double>(q.n_noise_events) : NAN;
  if (completeness.empty()) {
    q.completeness_median = NAN;
  } else {
    std::sort(completeness.begin(), completeness.end());
    const std::size_t m = completeness.size();
    q.completeness_median = m % 2 ? completeness[m / 2] : 0.5 * (completeness[m / 2 - 1] + completeness[m / 2]);
  }
  return q;
}

}  // namespace celc
