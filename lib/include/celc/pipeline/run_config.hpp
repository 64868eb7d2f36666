#pragma once
/// \file run_config.hpp
/// The configuration of `celc run` / `celc batch`: one YAML schema (units in
/// config/run.yaml) mapped onto the options of every stage. Unknown keys and
/// wrong types are errors naming the file, the line and the key.
#include <cstdint>
#include <string>
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/cluster/to_observations.hpp"
#include "celc/eval/gt_velocity.hpp"
#include "celc/io/event_reader.hpp"
#include "celc/io/imu_window.hpp"
#include "celc/io/window_source.hpp"
#include "celc/pipeline/accelerometer.hpp"
#include "celc/pipeline/imu_still.hpp"
#include "celc/pipeline/window_policy.hpp"
#include "celc/solver/solver.hpp"

namespace celc {

/// Where a window's angular velocity comes from.
enum class OmegaSource {
  Gyro,   ///< the recording's gyroscope (imu.txt or the aedat IMU), the default
  Fixed,  ///< a constant given in the configuration (recordings without IMU)
};
std::string toString(OmegaSource source);  ///< "gyro" | "fixed"

/// Whether the gyro bias is taken from the recording's first still second
/// (pipeline/imu_still.hpp; motion.gyro_bias_from_still).
enum class StillBias {
  Auto,  ///< when there is one and its mean rate is significant (kStillBiasZ, kStillBiasMinRate)
  On,    ///< always; the run fails without a still second ("true")
  Off,   ///< never ("false")
};
std::string toString(StillBias mode);  ///< "auto" | "true" | "false"

/// StillBias::Auto subtracts a still second's mean rate when it stands out of
/// the noise: on some axis at least kStillBiasZ standard errors
/// (std / sqrt(samples)) from zero, and at least kStillBiasMinRate [rad/s]
/// in norm (0.3 deg/s: below it a bias moves v by a few tenths of a degree,
/// and slow drifts of the sensor's zero rate are of that size).
inline constexpr double kStillBiasZ = 5.0;
inline constexpr double kStillBiasMinRate = 0.005;

struct RunConfig {
  ReaderOptions reader;
  /// How windows are cut (pipeline/window_policy.hpp): by default each grows
  /// until its lines show parallax_px of translation (parallax). The events
  /// and seconds policies use `windows` (events_per_window or
  /// seconds_per_window; the paper's choice is 30,000 events); with them the
  /// last, partial window is processed when it holds at least half a window.
  WindowPolicy window_policy = WindowPolicy::Parallax;
  WindowOptions windows = [] {
    WindowOptions w;
    w.partial_min_share = 0.5;
    return w;
  }();
  ParallaxWindowOptions parallax;
  /// A bound on the memory of the windows in flight, by their events
  /// (SequenceRunner::run, core/parallel.hpp JobWeightBound): the next
  /// window is read only while the windows read and not yet worked on to
  /// the end leave room for one as large as the last, so that they hold at
  /// most this many events together when the windows are alike; with none
  /// in flight a window is read whatever it holds. 0 = no bound (only the
  /// count, threads + 2). A window holds 24 B per event, and about 100 B
  /// more per event while it is worked on (docs/performance.md). A window
  /// that leaves no room beside it for another of its size clusters on
  /// every worker's thread. Changes no result.
  std::size_t max_events_in_flight = 1000000;
  /// The rotation within a window: the gyro's samples integrated
  /// (gyro_integrated, the default: a hand-held camera's rate changes within
  /// a window; docs/accuracy.md) or the window's mean rate (constant_twist,
  /// the paper's model). The velocity is constant in the body frame either way.
  MotionModelKind motion = MotionModelKind::GyroIntegrated;
  OmegaSource omega_source = OmegaSource::Gyro;
  Vec3 fixed_omega = Vec3::Zero();  ///< [rad/s], camera frame, with OmegaSource::Fixed
  /// Constant gyroscope bias [rad/s], IMU frame: subtracted from every gyro
  /// sample before the calibration's R_cam_imu rotates it into the camera frame
  /// (SequenceRunner, where the gyro track is built). `celc info` reports the
  /// mean rate over the recording's first still second, an estimate of it.
  Vec3 gyro_bias = Vec3::Zero();
  /// Or take the bias as the mean gyro rate over the recording's first still
  /// second (pipeline/imu_still.hpp, what `celc info` reports): Auto (the
  /// default) when there is one and its mean is significant (kStillBiasZ,
  /// kStillBiasMinRate), unless gyro_bias is set; On always, the run failing
  /// without a still second or with gyro_bias set; Off never.
  StillBias gyro_bias_from_still = StillBias::Auto;
  GyroWindowOptions gyro;
  /// The accelerometer for celc_acc's check, with gravity from the first
  /// still second (pipeline/accelerometer.hpp).
  AccelerometerOptions accelerometer;
  ClusterOptions cluster;
  ObservationOptions observations;
  /// The solvers' defaults (solver/options.hpp): the library's and the tool's are one.
  SolverOptions solver;
  std::vector<Method> methods = runMethods();
  GtVelocityOptions groundtruth;
  std::uint64_t seed = 1;  ///< seeds the solvers' random row subsets (per window: seed + index)
  std::string validate() const;
  /// The `windows:` section's problems ("key: what; "), by policy.
  std::string windowsValidate() const;
};

/// The schema of `celc run` / `celc batch` configurations (core/fields.hpp):
/// input, windows, motion, cluster, lines, observations, solver, methods,
/// groundtruth, seed.
void describe(FieldVisitor& v, RunConfig& config);
/// The `cluster:` and `lines:` sections alone, as in a run configuration
/// (config/cluster.yaml; `celc cluster -c`).
void describeClustering(FieldVisitor& v, ClusterOptions& cluster, LineFitOptions& lines);

/// Applies a YAML document onto `config` (absent keys keep their values),
/// then validates. Throws ConfigError naming the origin, line and key.
void applyRunConfig(const std::string& yaml, const std::string& origin, RunConfig& config);
/// Reads a file with applyRunConfig onto the defaults.
RunConfig loadRunConfig(const std::string& path);
/// Applies `key.path=value` (a YAML value) onto `config`, then validates.
void applyRunSetting(const std::string& assignment, RunConfig& config);
/// Applies every assignment, then validates once (keys that only make sense
/// together, e.g. windows.policy and windows.seconds, may come in any order).
void applyRunSettings(const std::vector<std::string>& assignments, RunConfig& config);
/// The effective configuration as YAML (every key, with its unit and doc).
std::string toYaml(const RunConfig& config);

/// Keys that do not change a run's rows, left out of configuration
/// comparisons (resume, table grouping): `cluster.threads` (the clustering of
/// one window gives the same clusters on any number of threads; `--threads`
/// sets it), `windows.read_batch` (how many events are read at a time) and
/// `windows.max_events_in_flight` (how many windows are worked on at once).
const std::vector<std::string>& resultNeutralKeys();

/// The first field (in schema order, result-neutral keys left out) whose
/// value differs, as "key: A vs B" with the YAML values; "" when none does.
std::string firstConfigDifference(const RunConfig& a, const RunConfig& b);

}  // namespace celc
