#pragma once
/// \file cluster_quality.hpp
/// How well a window's clusters match the edges that made its events, where
/// the truth is known (`celc synth`'s labels.txt, the simulators' labels).
///
/// Over one window, with `clusters[i]` the pipeline's cluster of event i
/// (-1 = not clustered) and `edges[i]` its true edge (-1 = a noise event):
///   purity        = sum over clusters of (events of its majority edge)
///                   / (events in clusters): event-weighted; noise events in
///                   a cluster count against it;
///   completeness  of an edge = (its events in its largest cluster) / (its events);
///   coverage      = (edge events in any cluster) / (edge events);
///   noise admitted = (noise events in any cluster) / (noise events).
/// Only edges with at least `min_edge_events` events in the window count as
/// edges of the window (a few events at a window's border are no line).
#include <cstddef>
#include <vector>

namespace celc {

struct ClusterQualityOptions {
  std::size_t min_edge_events = 20;  ///< [events] an edge with fewer in the window is not counted
  double pure_share = 0.95;          ///< [-] a cluster below this purity counts as impure
  double complete_share = 0.8;       ///< [-] an edge with this share in one cluster counts as complete
};

struct ClusterQuality {
  int n_clusters = 0;             ///< clusters with at least one event
  int n_impure = 0;               ///< clusters whose purity is below pure_share
  int n_edges = 0;                ///< edges with at least min_edge_events events
  int n_edges_complete = 0;       ///< of them, with complete_share of their events in one cluster
  int n_edges_covered = 0;        ///< of them, the majority edge of at least one cluster
  double purity = 0.0;            ///< [-] event-weighted; NaN without clustered events
  double completeness_median = 0.0;  ///< [-] median over the counted edges; NaN without edges
  double coverage = 0.0;          ///< [-] NaN without edge events
  double noise_admitted = 0.0;    ///< [-] NaN without noise events
  std::size_t n_clustered = 0, n_edge_events = 0, n_noise_events = 0;
};

/// The measures above for one window; `clusters` and `edges` have one entry
/// per event (std::invalid_argument when their sizes differ).
ClusterQuality measureClusterQuality(const std::vector<int>& clusters, const std::vector<int>& edges,
                                     const ClusterQualityOptions& options = {});

}  // namespace celc
