#pragma once
// Internal: fragments of one edge, found among a window's clusters.
#include <cstddef>
#include <vector>

#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"
#include "moving_line.hpp"

namespace celc::detail {

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
