#pragma once
// Internal: fragments of one edge, found among a window's clusters.
#include <cstddef>
#include <vector>

#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc::detail {

/// The moving line of a cluster in the reference frame of the motion model:
/// the plane normal n(t) = N1 + (t - t1) / (t3 - t1) (N3 - N1), N = R(t) m of
/// its fitted l1 (at t1) and l3 (at t3), exact for a camera translating at
/// constant velocity (lines/line_fit.hpp, the moving model).
struct MovingLine {
  Vec3 n1, n3;
  double t1 = 0.0, t3 = 0.0;
  Vec3 at(double t) const { return n1 + (t - t1) / (t3 - t1) * (n3 - n1); }
};

/// Groups of clusters (indices into `clusters`, each group ascending; every
/// cluster with lines in exactly one group) that are fragments of one edge:
/// two clusters join when the median distance of each one's events to the
/// other's moving line, within the other's time span, is at most merge_px
/// [px] (both ways, on up to 48 events each). An edge broken by its texture,
/// by a change of polarity along it (a chessboard's lines) or by an occluder
/// then gives one cluster, whose longer extent fixes its lines better.
/// Clusters without lines are in no group.
std::vector<std::vector<std::size_t>> fragmentGroups(const std::vector<ClusterObservation>& clusters,
                                                     double focal_px, const MotionModel* motion,
                                                     double merge_px);

}  // namespace celc::detail
