#pragma once
/// \file to_observations.hpp
/// From a clustered window to what the solvers see: per cluster its events as
/// undistorted bearings (sorted by time) and its fitted boundary lines l1, l2, l3.
#include <functional>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/cluster/cluster.hpp"
#include "celc/lines/line_fit.hpp"
#include "celc/core/observations.hpp"

namespace celc {

/// Pixel (x right, y down) -> undistorted bearing (x, y, 1), e.g.
/// [&](const Vec2& p) { return camera.bearing(p); }.
using BearingFunction = std::function<Vec3(const Vec2&)>;

struct ObservationOptions {
  LineFitOptions lines;      ///< l1 / l2 / l3 fitting (interval, minimum events, quality)
  int min_events = 20;       ///< clusters with fewer usable events are skipped
  /// Clusters whose events lie within this median distance of each other's
  /// moving line (both ways) are fragments of one edge and become one
  /// cluster [px]; 0 = never joined.
  double merge_px = 1.0;
  std::string validate() const;  ///< empty when valid
};
/// The schema of the `observations:` section; its `lines` are the top-level
/// `lines:` section of a configuration (core/fields.hpp).
void describe(FieldVisitor& v, ObservationOptions& options);


/// What happened to each cluster.
struct ObservationReport {
  /// Per input event: the ClusterResult id of the cluster it ends in, after
  /// the fragments of one edge are joined; -1 when in none (unclustered, a
  /// non-finite bearing, a cluster with too few events).
  std::vector<int> event_clusters;
  int n_clusters = 0;         ///< clusters in the ClusterResult
  int n_used = 0;             ///< clusters turned into observations with lines
  int n_too_few_events = 0;   ///< skipped: fewer than min_events usable events
  /// l1 or l3 not Ok (too few events, poor fit, l3 not after l1): kept with
  /// has_lines = false (npt uses them; the line methods skip them)
  int n_line_fit_failed = 0;
  int n_merged = 0;           ///< clusters joined into another (fragments of one edge, merge_px)
  std::vector<int> merged_ids;       ///< ClusterResult ids of the clusters joined into another
  std::vector<int> merged_into;      ///< the id each of merged_ids was joined into
  std::vector<int> used_ids;         ///< ClusterResult ids of the clusters used, in output order
  std::vector<ClusterLines> lines;   ///< fitted lines of every used cluster (quality, timestamps)
  std::vector<int> failed_ids;              ///< ClusterResult ids of the clusters whose lines failed
  std::vector<ClusterLines> failed_lines;   ///< their fits (statuses say why)
};

/// Events already labelled by cluster (`celc solve`, the Python module) as a
/// clustering result: clusters numbered in ascending label order, each
/// ClusterStats::id the given label, size / t_begin / t_end [s] / on (the
/// polarity of its first event) filled in; a negative label = unassigned (-1).
/// Status Ok, NoClusters when no event is labelled. Throws
/// std::invalid_argument when the sizes differ.
ClusterResult clustersFromLabels(const std::vector<Event>& events, const std::vector<int>& labels);

/// `celc solve`'s input (the CLI and the Python module): what follows from
/// events labelled by cluster.
struct LabelledObservations {
  ClusterResult clusters;  ///< clustersFromLabels
  /// motion_from(t_first), t_first the first clustered event's time [s] (0
  /// without clusters): the motion's reference time, and so the camera frame
  /// of the solvers' v.
  MotionModel motion = MotionModel::constantTwist(Vec3::Zero(), 0.0);
  WindowObservations observations;  ///< toObservations with that motion
  ObservationReport report;
};
LabelledObservations observeLabelledEvents(const std::vector<Event>& events, const std::vector<int>& labels,
                                           const BearingFunction& bearing, double focal_px,
                                           const ObservationOptions& options,
                                           const std::function<MotionModel(double)>& motion_from);

/// Builds the solver input of a window. Clusters keep their ClusterResult id in
/// ClusterObservation::id; a cluster whose lines could not be fitted is kept
/// with has_lines = false. Events whose bearing is not finite are left out.
/// `focal_px` converts normalised distances to pixels (fit thresholds are in px)
/// and is stored in WindowObservations::focal_px. `motion` gives the rotation
/// the line fit removes (line_fit.hpp; nullptr: no rotation). Never throws on data.
/// `members`, when given: per output cluster, the indices into `events` of
/// its times and bearings, in their order (restoreObservationEvents).
/// The clusters' events and lines are built on `threads` threads (each
/// cluster from its own events, so the result is the same for any count);
/// `bearing` must then be safe to call from several threads.
WindowObservations toObservations(const std::vector<Event>& events, const ClusterResult& clusters,
                                  const BearingFunction& bearing, double focal_px,
                                  const ObservationOptions& options, const MotionModel* motion,
                                  ObservationReport* report = nullptr,
                                  std::vector<std::vector<int>>* members = nullptr, int threads = 1);

/// Frees the clusters' times and bearings (32 B per event), keeping their
/// ids and lines: a window's observations while another set is built.
void dropObservationEvents(WindowObservations& obs);

/// Fills the clusters' times and bearings again from the window's events and
/// toObservations' `members` (the same events and bearing function): the
/// very values toObservations stored, in its order.
void restoreObservationEvents(WindowObservations& obs, const std::vector<Event>& events,
                              const std::vector<std::vector<int>>& members, const BearingFunction& bearing);

}  // namespace celc
