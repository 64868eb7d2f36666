#pragma once
// Internal: the checks that decide whether a window can give a velocity at
// all, before any method runs (usable clusters, parallax).
#include <vector>

#include "celc/solver/solver.hpp"

namespace celc::detail {

/// Usable clusters (indices, ascending): at least min_events events, as many
/// bearings as times, finite non-zero l1 and l3 normals, l3 after l1.
std::vector<int> usableClusters(const WindowObservations& obs, int min_events);

/// Parallax of one cluster: robust scales (1.4826 MAD) [px] of its
/// rotation-compensated events about one static line (the plane normal n
/// minimising sum (n.f)^2) and about a line moving linearly in time
/// (n(tau) = n0 + tau n1, tau in [-1, 1] over the cluster). Both 0 below 8 events.
struct ClusterParallax {
  double static_px = 0.0;
  double moving_px = 0.0;
};
ClusterParallax clusterParallax(const ClusterObservation& c, const MotionModel& motion,
                                double focal_px, int max_events);

/// True (and `result` set to a Degenerate result) when fewer than
/// options.min_clusters clusters are usable, or, with check_parallax, when
/// fewer than min_clusters of the clusters with >= 8 events show parallax
/// (static scale >= min_parallax_px and >= min_parallax_ratio x moving scale).
bool windowIsDegenerate(const WindowObservations& obs, const MotionModel& motion,
                        const std::vector<int>& usable, const LinearOptions& options,
                        bool check_parallax, SolverResult& result);

/// checkWindow (solver.hpp) with the parallax test optional.
SolverResult checkWindow(const WindowObservations& obs, const MotionModel& motion,
                         const LinearOptions& options, bool check_parallax);

}  // namespace celc::detail
