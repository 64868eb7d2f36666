#pragma once
/// \file cluster.hpp
/// Space-time clustering of the events of one window into line clusters.
///
/// Each event becomes the point (x, y, c*t) [px, px, px]: pixel coordinates
/// and time scaled by a speed c [px/s] (relative to the window's first event).
/// A straight edge moving over the image triggers events on a smooth surface
/// in this space (a plane for constant image motion), so regions of
/// consistent local plane normals are line clusters. c makes time comparable
/// to pixels: with c close to the edges' image speed the event surfaces lean
/// at about 45 degrees and neighbourhoods are isotropic.
///
/// Region growing criteria (both methods, as pcl::RegionGrowing): seeds are
/// taken in order of increasing curvature; a neighbour joins the region when
/// the angle between its normal and the current point's normal is below
/// `smoothness_deg`; it is grown from further only when its curvature
/// (lambda_min / (lambda_0 + lambda_1 + lambda_2) of its neighbourhood's
/// covariance) is below `curvature_threshold`.
///
/// After growing, every cluster is checked: a plane is fitted (PCA) to its
/// points; a cluster whose RMS plane distance exceeds `max_plane_rms_px` is
/// split by sequential RANSAC plane extraction (two lines merged into one
/// region), and what is still not planar is rejected; clusters smaller than
/// `min_cluster_size` events, shorter than `min_time_span_s` or spatially
/// shorter than `min_extent_px` are dropped. Their events become noise (-1).
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc {

enum class ClusterMethod {
  Grid,  ///< own region grower; neighbours from a pixel window and a time range (fast, default)
  Pcl,   ///< reference: pcl::NormalEstimationOMP (k nearest, kd-tree) + pcl::RegionGrowing
};
/// "grid" / "pcl".
ClusterMethod parseClusterMethod(const std::string& name);
std::string toString(ClusterMethod method);
/// Empty when `method` can run in this process, else why not in one line:
/// the pcl method's library (libcelc_cluster_pcl.so, beside
/// libcelc_cluster.so) is opened here, on the first call that names it, and
/// may be missing. clusterEvents answers `invalid_options` with this reason;
/// callers check it before a run to fail at once.
std::string clusterMethodProblem(ClusterMethod method);

struct ClusterOptions {
  ClusterMethod method = ClusterMethod::Grid;
  /// Time scale c [px/s]: points are (x, y, c*t). 0 = automatic: c_speed_factor
  /// times the median normal-flow speed of a first pass (ClusterResult::c_px_per_s).
  double c_px_per_s = 0.0;
  /// Automatic c = this factor x the median normal-flow speed [-]: at 1 an edge
  /// at the median speed leaves a surface at 45 deg in (x, y, c*t), and its
  /// time neighbourhoods (+-time_radius_px / c) span the time it takes to move
  /// time_radius_px; at f > 1, 1/f of it (docs/clustering.md, "Choosing c").
  double c_speed_factor = 1.0;
  /// Automatic c is clamped to [c_min, c_max] [px/s].
  double c_min_px_per_s = 20.0;
  double c_max_px_per_s = 20000.0;
  bool separate_polarity = true;  ///< cluster ON and OFF events separately (paper)
  /// `celc run` clusters the window's events turned back by the gyro's
  /// rotation to the window's middle (derotate.hpp), so that an edge sweeping
  /// across the image stays one slowly moving line; the parallax probes and
  /// every later stage use the events as recorded. Off by default: on the
  /// held-out scenes it makes more edges whole but fewer clusters pure, and
  /// celc_ml no closer to the oracle (docs/clustering.md).
  bool derotate = false;

  // Neighbourhoods.
  int neighbours = 30;          ///< Pcl: k nearest neighbours for growing (and normals if pcl_normal_radius_px = 0) [events]
  /// Pcl: normals from all points within this radius in (x, y, c*t) [px]; 0 = k nearest.
  /// k nearest on a surface ~1 px thick gives curvatures above any useful threshold.
  double pcl_normal_radius_px = 3.0;
  int grid_radius_px = 2;       ///< Grid: normals from a (2r+1)^2 pixel window [px] (2 -> 5x5)
  int grow_radius_px = 1;       ///< Grid: growing visits a (2r+1)^2 pixel window [px] (1 -> 3x3)
  double time_radius_px = 2.5;  ///< Grid, normals: time range +-time_radius_px / c [s], i.e. in c*t units [px]
  double grow_time_radius_px = 2.5;  ///< Grid, growing: time range in c*t units [px]
  /// Grid: an event within normal_reuse_px / c seconds after the previous event of
  /// its pixel whose normal was computed reuses that normal [px of c*t]; 0 = never.
  double normal_reuse_px = 0.25;
  int min_neighbours = 5;       ///< Grid: fewer neighbours -> no normal, the event joins no region

  // Region growing.
  double smoothness_deg = 20.0;       ///< max angle between neighbouring normals [deg]
  /// Grid: the angle used is smoothness_noise_factor x the window's median
  /// angle between neighbouring normals (what noise alone gives), within
  /// [smoothness_min_deg, smoothness_deg]: on clean events a looser angle lets
  /// regions cross where two edges meet (docs/clustering.md, "The smoothness
  /// angle"); 0 = smoothness_deg always.
  double smoothness_noise_factor = 3.0;  ///< [-]
  double smoothness_min_deg = 3.0;       ///< [deg]
  double curvature_threshold = 0.15;  ///< max curvature of a point grown from [-] (0..1/3)
  int min_cluster_size = 60;          ///< [events]
  int max_cluster_size = 2000000;     ///< [events]

  // Checks after growing.
  double max_plane_rms_px = 1.5;   ///< max RMS distance to the cluster's plane [px]
  double ransac_threshold_px = 1.5;  ///< inlier distance when splitting [px]
  int max_split = 4;               ///< at most this many planes (or moving lines) extracted from one region
  /// A cluster is cut to the events that one moving line explains within this
  /// distance [px], by sequential RANSAC (line_split.hpp; needs the camera and
  /// the rotation, so `celc run` does it after clusterEvents); 0 = not cut.
  double line_split_px = 2.0;
  /// After the cut, a part whose median distance to its moving line [px]
  /// exceeds this many times the window's (the event-weighted median part's,
  /// at least 0.25 px; 6 parts at least) is dropped: a corner's two edges that
  /// one line fits within line_split_px (line_split.hpp); 0 = every part
  /// kept, else >= 1. Off: it raises purity without bringing celc_ml nearer
  /// the oracle (docs/decisions.md).
  double line_scale_ratio = 0.0;
  /// After the cut, the events in no cluster (left out by the growing, its
  /// checks or the cut) are grouped where they touch on a grid of this cell
  /// [px] in (x, y, c t), one polarity per group, and each group is cut to
  /// moving lines the same way (line_split.hpp): low-contrast edges too sparse
  /// for the growing's neighbourhoods. 0 = not recovered, else >= 1. Off:
  /// coverage 0.86-0.89 -> 0.93-0.97, but purity falls and celc_ml comes no
  /// nearer the oracle on balance (docs/decisions.md).
  double recover_cell_px = 0.0;
  /// After a first solve, the clusters are redrawn under the window's
  /// estimated motion (motion_reassign.hpp; `celc run` keeps them where the
  /// first method still answers on them and they hold 95% of the events):
  /// an event joins the one cluster whose line passes within this distance
  /// [px] (or 2.5 of its robust scales); 0 = not redrawn.
  double motion_reassign_px = 1.5;
  /// Redraws at most, each from the answer on the last kept clusters; the
  /// alternation stops at the first redraw not kept.
  int motion_redraw_rounds = 3;
  /// ... and clusters whose parts are both within this median distance [px]
  /// of their joint line under the motion join (fragments of one edge); 0 = none join.
  double motion_join_px = 0.0;
  double min_time_span_s = 0.0005; ///< minimum duration of a cluster [s]
  double min_extent_px = 5.0;      ///< minimum spatial extent of a cluster [px]
  /// Minimum density on the cluster's plane [events/px^2], area = 12 sqrt(l1 l2) from the
  /// two largest eigenvalues of its (x, y, c*t) covariance: rejects sparse noise "planes".
  double min_density_per_px2 = 0.25;

  int threads = 2;  ///< worker threads (normals; the two polarities)
  unsigned seed = 1;  ///< RANSAC seed (results are deterministic)

  std::string validate() const;  ///< empty when valid, else what is wrong
};
/// The schema of the `cluster:` section (core/fields.hpp).
void describe(FieldVisitor& v, ClusterOptions& options);


enum class ClusterStatus {
  Ok,              ///< at least one cluster
  EmptyWindow,     ///< no events
  TooFewEvents,    ///< fewer valid events than min_cluster_size
  NoClusters,      ///< events, but no region passed the checks (all noise)
  InvalidOptions,  ///< options.validate() failed; see ClusterResult::message
};
std::string toString(ClusterStatus status);

/// Per-cluster statistics; the plane is fitted in (x, y, c*t) [px].
struct ClusterStats {
  int id = -1;             ///< label used in ClusterResult::labels
  int size = 0;            ///< events
  bool on = true;          ///< polarity (true for every cluster when polarities are merged and mixed)
  double t_begin = 0.0, t_end = 0.0;  ///< first and last event time [s]
  Vec3 plane_normal = Vec3::UnitZ();  ///< unit normal in (x, y, c*t)
  Vec3 centroid = Vec3::Zero();       ///< (x [px], y [px], c*(t - t0) [px])
  double plane_rms_px = 0.0;          ///< RMS distance to the plane [px]
  double density_per_px2 = 0.0;       ///< events per px^2 of the plane (see min_density_per_px2)
  double extent_px = 0.0;             ///< spatial extent (largest pixel-space spread) [px]
  /// Normal-flow speed of the plane [px/s]: c * |n_t| / |(n_x, n_y)|.
  double speed_px_per_s = 0.0;
};

/// Where the events that joined no cluster went [events]: with n_clustered
/// they add up to n_events.
struct ClusterLosses {
  int invalid = 0;        ///< non-finite fields or pixels outside [0, 4096) px
  int no_region = 0;      ///< no normal (too few neighbours, or on one spot or line) or grown into no region
  int small_region = 0;   ///< in a region of fewer than min_cluster_size (or more than max_cluster_size) events
  int failed_checks = 0;  ///< in a region or plane shorter, smaller or sparser than min_time_span_s,
                          ///< min_extent_px, min_density_per_px2
  int off_planes = 0;     ///< in a non-planar region, on none of the planes split from it
  int off_moving_lines = 0;  ///< taken out by the moving-line cut (splitByMovingLines, line_split.hpp)
};

/// Why one event is in no cluster (ClusterResult::loss): the ClusterLosses
/// field it is counted in.
enum class LossReason : std::uint8_t { None, Invalid, NoRegion, SmallRegion, FailedChecks, OffPlanes, OffMovingLines };
struct ClusterResult {
  ClusterStatus status = ClusterStatus::EmptyWindow;
  std::string message;             ///< reason when not Ok
  std::vector<int> labels;         ///< per input event: cluster id (index into clusters) or -1
  std::vector<ClusterStats> clusters;
  double c_px_per_s = 0.0;         ///< time scale actually used [px/s]
  int n_events = 0, n_clustered = 0;
  int n_regions = 0;               ///< regions grown before the checks
  int n_split = 0, n_rejected_planar = 0, n_rejected_small = 0;
  ClusterLosses left_out;          ///< where the unclustered events went
  /// Per input event, where it went when in no cluster (None when clustered);
  /// filled by clusterEvents and splitByMovingLines, empty from other producers.
  std::vector<LossReason> loss;
  /// The smoothness angle the growing used [deg] (the larger of the polarities'
  /// with separate_polarity; ClusterOptions::smoothness_noise_factor).
  double smoothness_deg = 0.0;
  double t0 = 0.0;                 ///< time origin of c*t [s] (first event)
  /// Timings [ms]: grid index + time scale estimate, normals, growing, checks,
  /// whole call (per-group phases summed over the groups, which may run in parallel).
  double ms_time_scale = 0.0, ms_normals = 0.0, ms_grow = 0.0, ms_post = 0.0, ms_total = 0.0;
};

/// Clusters the events of one window. Events need not be sorted; events with
/// non-finite fields or pixels outside [0, 4096) get label -1. Never throws on data; returns a status.
ClusterResult clusterEvents(const std::vector<Event>& events, const ClusterOptions& options);

/// The median normal-flow speed [px/s] of local planes fitted with a first
/// guess of c (iterated up to 4 times); clusterEvents' automatic c is
/// c_speed_factor times it. Returns 0 when there are too few events to say.
double estimateTimeScale(const std::vector<Event>& events, const ClusterOptions& options);

}  // namespace celc
