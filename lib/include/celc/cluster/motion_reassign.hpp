#pragma once
/// \file motion_reassign.hpp
/// Clusters redrawn under the window's estimated motion: each cluster's 3D
/// line given the velocity direction, fragments of one line joined, and every
/// clustered event given to the one line that explains it.
///
/// With the window's rotation R(t) and the camera centre c(t) = P(t) v
/// (motion_model.hpp; v the estimated unit velocity, so lengths are in units
/// of the speed times one second), a 3D line with direction d and moment
/// m = X x d (X any of its points) is seen at time t in the plane through
/// c(t) and the line, whose normal is m - c(t) x d. An event with
/// reference-frame bearing g = R(t) f lies on it when
///   g^T m - (g x c(t))^T d = 0,
/// linear in h = (m, d): a cluster's line is the smallest eigenvector of the
/// 6 x 6 normal matrix of its events' rows, reweighted (IRLS, Huber at 1 px)
/// so that the residual is the distance in pixels in the image at t,
///   focal |n^T g| / sqrt(|n|^2 - (n^T z)^2),   z = R(t) e_z.
/// Unlike splitByMovingLines' line of its own (5-9 free parameters in time),
/// this line has 4: one v ties every cluster's motion, so a fragment's line
/// extrapolates over the whole window, and two fragments of one edge fit
/// one line.
#include <cmath>
#include <memory>
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/cluster/to_observations.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc {

struct MotionLinesFit;

/// A window's clusters with their lines under one motion and velocity, as
/// reassignToMotionLines fits them (step 1 below), and the window's cost
/// under them (motionCost). Made by fitMotionLines; a redraw of the same
/// labels under the same v takes it instead of fitting the lines again.
class MotionLines {
 public:
  MotionLines();
  ~MotionLines();
  MotionLines(MotionLines&&) noexcept;
  MotionLines& operator=(MotionLines&&) noexcept;
  /// motionCost of the labels under v; NaN when nothing was fitted.
  double cost() const { return cost_; }
  /// Whether these are the lines of `labels` under `v`.
  bool fittedFor(const std::vector<int>& labels, const Vec3& v) const;

 private:
  friend MotionLines fitMotionLines(const std::vector<Event>&, const std::vector<int>&, const BearingFunction&,
                                    double, const MotionModel&, const Vec3&, const ClusterOptions&);
  friend struct MotionLinesAccess;
  std::unique_ptr<MotionLinesFit> lines_;  ///< null when nothing was fitted
  std::vector<int> labels_;
  Vec3 v_ = Vec3::Constant(NAN);
  double cost_ = NAN;
};

/// The lines of the clusters `labels` under the motion and `v`, and the
/// window's cost under them (the arguments as for motionCost).
MotionLines fitMotionLines(const std::vector<Event>& events, const std::vector<int>& labels,
                           const BearingFunction& bearing, double focal_px, const MotionModel& motion, const Vec3& v,
                           const ClusterOptions& options);

/// What reassignToMotionLines did to a window's clusters.
struct MotionReassignReport {
  int n_lines = 0;        ///< clusters whose line under the motion was fitted
  int n_unexplained = 0;  ///< clusters the motion does not explain (robust scale above the threshold): kept as they were
  int n_joined = 0;       ///< clusters joined into another (fragments of one line)
  int n_moved = 0;        ///< clustered events given to another cluster
  int n_ambiguous = 0;    ///< events within the threshold of two lines (kept where their own line is one)
  int n_removed = 0;      ///< clustered events no line explains: made noise
  /// motionCost of the input clusters under v (from the same line fits); NaN
  /// when nothing was fitted.
  double cost = NAN;
};

/// Redraws the clusters `labels` (per event: a cluster id >= 0 or -1) of
/// `events` under the motion (R(t), P(t)) and the unit velocity `v`
/// (reference frame), in place, with threshold options.motion_reassign_px
/// [px] (see the file comment):
///  1. each cluster's line (m, d), and its robust scale s [px]; a cluster with
///     s above the threshold is left as it is (another motion, a curved edge);
///  2. clusters whose lines agree (directions and moments within 3 deg) join
///     when both parts' median distance to their joint line is within
///     options.motion_join_px [px] (0: none join; opposite polarities join
///     only with separate_polarity false);
///  3. every clustered event goes to the line nearest it among the groups
///     whose events lie within a few pixels and one twentieth of the
///     window's time of it (of a polarity the group holds) when that line
///     is within the threshold and no other is; an event within it of two
///     lines stays where it was if its own line is one of them (a corner,
///     two edges crossing: noise otherwise); an event within it of none
///     becomes noise (-1). Unclustered events stay noise: a line under any
///     motion near the right one claims the events beside it, so adding
///     them would lower the cost of a wrong answer as much as of a right one.
/// Ids of the result are compact (0 .. n-1, in order of first event). Does
/// nothing when the threshold is 0 or v is not finite. Deterministic; never
/// throws on data. `prefit`: the lines of step 1 when fittedFor(labels, v)
/// (made with the same events, bearing, focal, motion and options), taken
/// (moved from) instead of fitted again; the same result either way.
MotionReassignReport reassignToMotionLines(const std::vector<Event>& events, std::vector<int>& labels,
                                           const BearingFunction& bearing, double focal_px,
                                           const MotionModel& motion, const Vec3& v, const ClusterOptions& options,
                                           MotionLines* prefit = nullptr);

/// The window's cost under the motion (R(t), P(t)) and the unit velocity
/// `v` with the clusters `labels`: each cluster's line fitted as in
/// reassignToMotionLines, then the mean over every event with a finite time
/// of min((d / T)^2, 1), d its distance to its cluster's line and T =
/// options.motion_reassign_px; an event in no cluster (or in one without a
/// line) costs 1. Two clusterings of the same events under two velocities
/// compare on it: the alternation of clusters and motion keeps a redraw only
/// where it falls. NaN when nothing can be fitted (no cluster, threshold 0,
/// v not finite).
double motionCost(const std::vector<Event>& events, const std::vector<int>& labels, const BearingFunction& bearing,
                  double focal_px, const MotionModel& motion, const Vec3& v, const ClusterOptions& options);

}  // namespace celc
