#pragma once
/// \file line_split.hpp
/// Clusters cut to the events that one moving line explains.
///
/// Region growing joins what is locally smooth in (x, y, c t); where two
/// edges meet (a corner, a junction) a region can grow from one edge's
/// surface onto the other's. Under the window's rotation R(t) and a constant
/// velocity in the reference frame, an edge's events satisfy n(t)^T R(t) f = 0
/// with a plane normal linear in time (the plane through the centre c(t) and
/// the 3D line (P, d) has normal (P - c(t)) x d); a constant body-frame
/// velocity under rotation bends c(t), which a quadratic term takes:
///   n(t) = a + s b + s^2 c,   s = (t - t_mid) / (t_end - t_begin),   |a| = 1.
/// Each cluster is split by sequential RANSAC over such moving lines: samples
/// of 5 events (one per fifth of the cluster's time) give lines linear in
/// time, scored at 1.5 times `line_split_px` (pixel distance in the image of
/// the camera at the event's time); the best is refitted with the quadratic
/// term on its inliers at 3, 2, 1.5 and 1 times the threshold and its
/// inliers become a cluster, then the next line among the rest, up to
/// ClusterOptions::max_split parts (2 max_split draws). Parts with fewer than
/// min_cluster_size events, a part within 3 thresholds (median) of an
/// earlier one's line (the tails of its residuals), and the events no line
/// explains become noise. Last, with ClusterOptions::line_scale_ratio > 0 and
/// at least 6 parts in the window, a part whose median distance to its line
/// exceeds that many times the window's (the event-weighted median of the
/// parts' medians, at least 0.25 px: whole-pixel rounding) is dropped: a
/// corner's two edges that one line fits within the threshold spread their
/// distances across it, where one edge's lie within its noise.
///
/// With ClusterOptions::recover_cell_px > 0, the events then in no cluster
/// (ClusterResult::loss: left out by the growing, its checks or the cut;
/// not the invalid ones) are grouped where they touch on a grid of that cell
/// in (x, y, c t), one polarity per group, and each group of at least
/// min_cluster_size events is cut by the same RANSAC (up to 16 lines). A
/// line becomes a cluster when it holds min_cluster_size events spanning
/// min_extent_px and its events' median distance is at most twice the
/// window's scale (the median of the other parts' medians, at least
/// 0.25 px): noise events within the threshold of a line spread over it. The
/// recovered events leave their ClusterLosses fields.
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/cluster/to_observations.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc {

/// What splitByMovingLines did to a window's clusters.
struct LineSplitReport {
  int n_split = 0;         ///< clusters cut into two or more moving lines
  int n_removed = 0;       ///< events taken out of clusters (no moving line within line_split_px)
  int n_dropped = 0;       ///< clusters left with fewer than min_cluster_size events explained
  int n_wide = 0;          ///< parts dropped by ClusterOptions::line_scale_ratio (their events in n_removed)
  int n_recovered = 0;         ///< clusters found among the left-out events (ClusterOptions::recover_cell_px)
  int n_recovered_events = 0;  ///< their events
};

/// Cuts every cluster of `clusters` to its moving lines (see the file
/// comment); new parts get ids after the existing ones and clusters are
/// renumbered in order of their first event, as clusterEvents does. `bearing`
/// and `focal_px` as in toObservations; `motion` gives R(t) (null: no
/// rotation). Does nothing when options.line_split_px is 0 or the status is
/// not Ok; a window whose clusters all vanish gets status NoClusters.
/// Deterministic for a given options.seed. Never throws on data.
LineSplitReport splitByMovingLines(const std::vector<Event>& events, ClusterResult& clusters,
                                   const BearingFunction& bearing, double focal_px, const MotionModel* motion,
                                   const ClusterOptions& options);

}  // namespace celc
