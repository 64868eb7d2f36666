#pragma once
/// \file render_sequence.hpp
/// A whole simulated recording: events from the rendering simulator, an IMU,
/// ground-truth poses, and the sequence directory `celc synth` writes.
///
/// IMU model (IMU at the camera centre, rotated by R_cam_imu: w_cam = R_cam_imu gyro):
///   gyro  = R_cam_imu^T w(t) + b_g + n_g,
///   accel = R_cam_imu^T (dv/dt + w x v - R_world_cam^T g_world) + b_a + n_a,
/// with v, w the camera-frame twist, g_world the gravity vector in the world
/// frame, and white noises of density sigma [unit/sqrt(Hz)], i.e. per-sample
/// std sigma * sqrt(rate). Ground truth: T_world_body = T_world_cam T_body_cam^-1.
///
/// Output directory (RPG text layout, no header lines):
///   events.txt       t x y p          [s, 6 decimals] [px] [px] {0, 1}
///   labels.txt       edge id per event line (-1: noise)
///   imu.txt          t ax ay az gx gy gz    [s] [m/s^2] [rad/s], IMU frame, from -imu.still_before_s
///   groundtruth.txt  t px py pz qx qy qz qw  T_world_body [s] [m]
///   twist.txt        t vx vy vz wx wy wz  true camera-frame twist at the GT times
///   calib.txt        fx fy cx cy k1 k2 p1 p2 k3
///   calib.yaml       docs/formats.md schema
///   twist.yaml       the trajectory definition and the run's parameters
///   edges.txt        id x0 y0 z0 x1 y1 z1  world end points of each scene edge [m]
/// Every file is written under a temporary name (.NAME.partial) and renamed
/// once all of them are complete.
#include <functional>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/geometry/camera.hpp"
#include "celc/sim/render.hpp"
#include "celc/sim/scene.hpp"
#include "celc/sim/scene_trajectory.hpp"

namespace celc {

struct ImuOptions {
  double rate = 1000.0;            ///< [Hz]
  double gyro_noise = 1e-4;        ///< white-noise density [rad/s/sqrt(Hz)]
  Vec3 gyro_bias = Vec3::Zero();   ///< [rad/s]
  double accel_noise = 1e-3;       ///< [m/s^2/sqrt(Hz)]
  Vec3 accel_bias = Vec3::Zero();  ///< [m/s^2]
  Mat3 R_cam_imu = Mat3::Identity();
  Vec3 gravity = Vec3(0.0, 9.81, 0.0);  ///< g in the world frame [m/s^2] (y down by default)
  /// [s] the IMU starts this long before the motion, the camera at rest at
  /// the initial pose (timestamps from -still_before_s): the still span from
  /// which `celc run` takes the gyro bias and gravity. The twist then starts
  /// at t = 0 without the accelerometer seeing the step.
  double still_before_s = 0.0;
  std::string validate() const;
};

struct GroundTruthOptions {
  double rate = 200.0;   ///< [Hz]
  RigidPose T_body_cam;  ///< identity by default
  std::string validate() const;
};

/// The schema of a scene's `imu:` and `groundtruth:` sections (core/fields.hpp).
void describe(FieldVisitor& v, ImuOptions& options);
void describe(FieldVisitor& v, GroundTruthOptions& options);

/// Everything `celc synth` needs (one SCENE.yaml).
struct SynthConfig {
  std::string source;  ///< the file it was read from
  uint64_t seed = 1;
  double duration = 0.5;  ///< [s]
  CameraModel camera;
  std::string camera_preset = "davis346";
  double background = 0.5;  ///< [0, 1]
  std::vector<PlaneSpec> planes;
  TrajectorySpec trajectory;
  RenderOptions events;
  ImuOptions imu;
  GroundTruthOptions groundtruth;
  std::string validate() const;  ///< empty when valid
};

/// IMU samples at t0, t0 + 1/rate, ... <= t1; at t < 0, when
/// options.still_before_s > 0, the camera rests at trajectory.pose(0).
std::vector<ImuSample> simulateImu(const Trajectory& trajectory, const ImuOptions& options,
                                   double t0, double t1, uint64_t seed);
/// Ground-truth poses T_world_body at t0, t0 + 1/rate, ... <= t1.
std::vector<PoseSample> groundTruthPoses(const Trajectory& trajectory,
                                         const GroundTruthOptions& options, double t0, double t1);

struct SynthSummary {
  RenderStats stats;
  int64_t events = 0;
  int64_t imu_samples = 0;
  int64_t poses = 0;
  double duration = 0.0;      ///< simulated [s]
  double wall_seconds = 0.0;  ///< simulation + writing [s]
};

/// Progress: simulated time so far [s] and events so far.
using SynthProgress = std::function<void(double t, int64_t events)>;

/// Simulates the configured sequence into `dir` (created if missing; existing
/// files of the layout are replaced). Throws std::runtime_error on I/O errors
/// and std::invalid_argument on an invalid config.
SynthSummary writeSequence(const SynthConfig& config, const std::string& dir,
                           const SynthProgress& progress = {});

/// Camera presets: "davis346" (346x260, f = 320 px) and "davis240" (240x180, f = 200 px),
/// no distortion. Throws std::invalid_argument for another name.
CameraModel cameraPreset(const std::string& name);

/// The schema of SCENE.yaml (core/fields.hpp): keys that do not apply (e.g.
/// `square` on a rectangles plane) are unknown keys.
void describe(FieldVisitor& v, SynthConfig& config);

/// Reads SCENE.yaml. Unknown keys, keys that do not apply and wrong types
/// throw ConfigError with "FILE:LINE: key 'a.b': ..." messages.
SynthConfig loadSynthConfig(const std::string& path);
/// The same from YAML text; `origin` names it in errors.
SynthConfig parseSynthConfig(const std::string& yaml, const std::string& origin);

}  // namespace celc
