#pragma once
/// \file line_scene.hpp
/// The paper's synthetic scene (Sec. 5.1): random 3D segments, a camera moving
/// with a constant twist (or with a varying gyroscope rate), events sampled as
/// random points on random lines at random times, projected with a pinhole
/// camera and perturbed by Gaussian pixel noise; boundary lines l1 / l2 / l3
/// from the true projections of the segment endpoints at t_s / t_m / t_e with
/// Gaussian noise on the endpoints. Library code: the tests, the benchmarks and
/// `celc simulate` use it.
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/geometry/camera.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"

namespace celc {

struct LineSceneOptions {
  int n_lines = 5;                    ///< 3D segments (clusters)
  int events_per_line = 200;          ///< events sampled per segment
  double duration = 0.5;              ///< window length [s]; t_s = 0, t_e = duration
  Vec3 velocity{1.0, 2.0, 0.0};       ///< v [m/s], body frame (constant twist) or reference frame
  Vec3 omega{0.0, 0.0, 2.0};          ///< w [rad/s], camera frame
  double event_noise_px = 2.0;        ///< std of event pixel noise [px]
  double line_noise_px = 2.0;         ///< std of line endpoint noise [px]
  double omega_noise = 0.0;           ///< std per axis of the angular velocity given to the solvers [rad/s]
  double outlier_fraction = 0.0;      ///< share of events replaced by uniform random pixels and times
  /// Every event of a line moved this far along the line's image normal, to a
  /// side drawn per line [px]: how real and rendered events sit off their edge
  /// (they fire part-way up the blurred log-intensity ramp). 0 = on the line.
  double edge_offset_px = 0.0;
  Vec2 x_range{-2.0, 2.0};            ///< segment endpoints x [m] (reference frame)
  Vec2 y_range{-2.0, 2.0};            ///< y [m]
  Vec2 z_range{3.0, 6.0};             ///< z (depth) [m]
  /// Camera: DAVIS346-like, 346x260, focal 320 px, centred principal point, no distortion.
  CameraModel camera{};
  /// ConstantTwist: the paper's model. GyroIntegrated: the rate varies as
  /// w(t) = omega + omega_wobble * sin(2 pi t / duration) (sampled at gyro_rate_hz)
  /// and v is constant in the reference frame.
  MotionModelKind motion = MotionModelKind::ConstantTwist;
  Vec3 omega_wobble{0.5, -0.3, 0.4};  ///< [rad/s], GyroIntegrated only
  double gyro_rate_hz = 1000.0;       ///< [Hz], GyroIntegrated only
  /// |a| [m/s^2]: a constant reference-frame acceleration beyond the motion
  /// model's velocity, p(t) = P(t) v + (t - t_s)^2 / 2 a, so that v is the
  /// velocity at t_s. Its direction is drawn per trial, uniform on the sphere
  /// and drawn again (up to 100 times) while a segment's endpoint comes
  /// closer than 0.5 m in depth during the window; nothing is drawn at 0.
  double acceleration = 0.0;
  /// When not empty: these segments (reference frame [m]) instead of random ones.
  std::vector<std::array<Vec3, 2>> fixed_segments;
  std::string validate() const;
};
/// The schema of the `scene:` section of `celc simulate` (core/fields.hpp).
void describe(FieldVisitor& v, LineSceneOptions& options);


/// One generated trial: what the solvers get, and the truth.
struct LineSceneTrial {
  WindowObservations observations;          ///< clusters with events and noisy l1, l2, l3
  MotionModel true_motion = MotionModel::constantTwist(Vec3::Zero(), 0.0);
  MotionModel given_motion = MotionModel::constantTwist(Vec3::Zero(), 0.0);  ///< with gyro noise
  Vec3 true_direction = Vec3::Zero();       ///< unit v (zero when the speed is zero)
  Vec3 true_acceleration = Vec3::Zero();    ///< a [m/s^2], reference frame
  std::vector<std::array<Vec3, 2>> segments;  ///< endpoints [m], reference frame
  std::vector<Event> pixel_events;          ///< the same events in pixels (outliers included)
  std::vector<int> labels;                  ///< per pixel event: cluster index, -1 for outliers
};

/// Generates one trial. Deterministic for a given rng state.
LineSceneTrial generateLineScene(const LineSceneOptions& options, std::mt19937_64& rng);

}  // namespace celc
