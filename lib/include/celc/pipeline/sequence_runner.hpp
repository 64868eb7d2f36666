#pragma once
/// \file sequence_runner.hpp
/// `celc run` on one recorded sequence: per window, the events, undistortion,
/// clustering, boundary lines, the gyroscope for the window, every solver,
/// then the ground-truth velocity and the metrics where poses exist.
/// Windows are read in order by the calling thread, processed by a pool of
/// workers, and handed to the sink in window order.
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "celc/eval/cluster_quality.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/window_dump.hpp"

namespace celc {

/// What a run reads. `events` is an RPG / UZH-FPV sequence directory
/// (events.txt, imu.txt, groundtruth.txt, calib.yaml or calib.txt inside) or a
/// single file (events text or aedat); explicit paths override the directory's.
struct RunInputs {
  std::string events;
  std::string calib;        ///< calibration YAML or calib.txt
  std::string groundtruth;  ///< pose file `t px py pz qx qy qz qw` (optional)
  std::string imu;          ///< IMU text file (optional; aedat files carry their own)
  /// The true edge of every event (`celc synth`'s labels.txt, io/truth_labels.hpp):
  /// each window's clusters are then measured against it and solved on its
  /// true clusters too (the oracle). Empty: a sequence directory's labels.txt
  /// when it has one; "none": no truth.
  std::string truth_labels;
};

/// A ROS bag or HDF5 file as the events input: the calibration (a bag's
/// sensor_msgs/CameraInfo) and the ground truth (its poses) come from the file
/// when `inputs` does not name them (`celc run`, `celc batch`, the Python
/// module). Other inputs are left as they are. Throws IoError naming the file.
void defaultContainerInputs(RunInputs& inputs, const ReaderOptions& reader);

/// One method's outcome in one window.
struct MethodRow {
  Method method = Method::Celc;
  SolverResult result;
  bool has_metrics = false;
  double eps = 0.0, phi = 0.0;  ///< |v_gt - v|, acos(v_gt . v) [rad] on unit vectors
};

/// Seconds spent per stage in one window (wall time of that window's worker).
struct StageTimes {
  double undistort = 0, cluster = 0, lines = 0, solve = 0, groundtruth = 0;
  double truth = 0;  ///< the clusters against the truth labels and the oracle's solve
  double redraw = 0; ///< the clusters redrawn under the first solve's motion, and solved again
};

struct WindowRecord {
  std::uint64_t index = 0;
  double t0 = 0.0, t1 = 0.0;   ///< [s]
  std::size_t n_events = 0;
  int n_clusters = 0;          ///< clusters handed to the solvers with lines
  int n_line_fit_failed = 0;   ///< clusters whose l1 / l3 could not be fitted (npt still uses them)
  /// The clustering and the moving-line cut (before any redraw): events in a
  /// cluster, and where the others went (0 where the window was not clustered).
  int n_events_clustered = 0;
  ClusterLosses left_out;
  /// The lines' translation D over the window [px] (pipeline/window_policy.hpp); NaN: not measured.
  double translation_px = NAN;
  /// Empty when the window reached the solvers; else why no method ran
  /// (`no_gyro`, `not_covered`, `gyro_gap`, `too_few_clusters`, `no_clusters`, ...).
  std::string window_status;
  std::vector<MethodRow> rows;  ///< one per configured method
  bool has_gt = false;
  Vec3 gt = Vec3::Zero();       ///< unit ground-truth direction (camera frame at t0)
  double gt_speed = 0.0;        ///< [m/s]
  /// The angular velocity the solvers used [rad/s], camera frame: the fixed
  /// one, or the window's mean gyro rate (gyro bias subtracted); has_omega
  /// false when the window has none (no_gyro, not_covered, gyro_gap).
  bool has_omega = false;
  Vec3 omega = Vec3::Zero();
  StageTimes times;
  /// With truth labels (RunInputs::truth_labels): the clusters against the
  /// true edges, and the oracle: celc_ml's phi [rad] on the window's true
  /// clusters (same lines code, motion and seed; NaN where it has no answer
  /// or there is no ground truth).
  bool has_truth = false;
  ClusterQuality quality;
  double oracle_phi = NAN;
};

/// Which windows to process (the others are read and skipped).
struct WindowFilter {
  std::int64_t after = -1;     ///< skip windows with index <= after (resume)
  int shard_index = 0;         ///< process index % shard_count == shard_index
  int shard_count = 1;
};

/// WindowRecord::n_events_clustered and left_out summed over a run [events].
struct RunClusterTotals {
  std::uint64_t clustered = 0, invalid = 0, no_region = 0, small_region = 0, failed_checks = 0, off_planes = 0,
                off_moving_lines = 0;
  void add(const WindowRecord& rec);
  /// Every event of the windows that were clustered.
  std::uint64_t events() const {
    return clustered + invalid + no_region + small_region + failed_checks + off_planes + off_moving_lines;
  }
};

struct RunStats {
  std::uint64_t windows_read = 0, windows_processed = 0;
  std::uint64_t events_read = 0, events_processed = 0;
  double seconds_total = 0.0, seconds_reading = 0.0;
  double seconds_probing = 0.0;  ///< of seconds_reading: the parallax policy's probes (clustering subsets)
  StageTimes stage_seconds;  ///< summed over windows
  std::uint64_t reader_warnings = 0;
  std::uint64_t clusters_line_fit_failed = 0;  ///< summed WindowRecord::n_line_fit_failed
  RunClusterTotals clustering;  ///< where the clustered windows' events went
  WindowTail tail;           ///< the last, partial window: processed or not, and its events
};

class SequenceRunner {
 public:
  /// Opens the inputs and loads calibration, IMU and poses. Throws
  /// IoError / ConfigError / std::runtime_error naming the file, also when
  /// the calibration's image size differs from the recording's sensor size
  /// (where the recording states one) and when the angular velocity comes
  /// from the gyroscope but the recording has no IMU samples.
  SequenceRunner(const RunInputs& inputs, const RunConfig& config);
  ~SequenceRunner();

  bool hasGroundTruth() const;
  bool hasImu() const;
  /// Human-readable description of what was opened (format, sensor, counts).
  std::vector<std::string> describe() const;

  /// Processes the windows; sink(record) is called on the calling thread in
  /// window order. progress(windows_done, events_done) likewise. Throws
  /// (naming windows.max_windows_per_second) when windows by event count come
  /// faster than that bound per second of data.
  RunStats run(int threads, const WindowFilter& filter,
               const std::function<void(const WindowRecord&)>& sink,
               const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

  /// Processes one window's events (the per-window pipeline; thread-safe).
  /// probe_px: with the parallax policy, the D that its probe measured when it
  /// chose the window's length (window_policy.hpp; NaN when it could not, as
  /// for the last window, cut by the end of the data); nullopt for the other
  /// policies. With the parallax policy a window whose D (the probe's, else
  /// the whole window's) is below windows.no_parallax_px is degenerate
  /// (no_parallax) for every method. cluster_threads > 0: the threads of the
  /// window's clustering instead of cluster.threads (the clusters do not
  /// depend on it; run() gives a window the workers that have nothing left to do).
  WindowRecord processWindow(std::uint64_t index, double t0, double t1, const std::vector<Event>& events,
                             std::optional<double> probe_px = std::nullopt, int cluster_threads = 0) const;

  /// Also write every clustered window for `celc solve` (window_dump.hpp)
  /// into context.dir; context.calib, gyro_integrated and seed are filled
  /// from the run's own.
  void dumpWindows(WindowDumpContext context);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace celc
