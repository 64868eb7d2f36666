#pragma once
/// \file peer_scene.hpp
/// The synthetic scene of the line-based peer solvers' comparisons (Gao et
/// al., CVPR 2024; Zhao et al., CVPR 2025), used by the peer study:
///  - pinhole camera, focal 320 px, 640 x 480, principal point at the centre;
///  - window of length T centred on t_ref; angular velocity |w| about a random
///    axis, constant; linear velocity |v| = V in a random direction, constant in
///    the reference camera frame (the peers' model: R(t) = exp(w^ tau),
///    p(t) = tau v, tau = t - t_ref, i.e. the GyroIntegrated motion model with a
///    constant rate, for which both CELC and npt are exact);
///  - per line, two endpoint pixels drawn uniformly in the image at t_ref, at
///    least min_separation_px apart, each at a depth (z) uniform in depth_range;
///    a segment is kept only if both endpoints project inside the image at both
///    ends of the window (else it is drawn again);
///  - per line events_per_line events, uniform in time over the window and
///    uniform along the 3D segment, Gaussian pixel noise sigma per axis; an
///    outlier share of them replaced by uniform random pixels at uniform random
///    times (they stay in the line's cluster, as mislabelled events);
///  - when no segment fits after max_attempts draws, the motion (both
///    directions) is drawn again: at V = 16 m/s (8 m in T = 0.5 s at depths of
///    2-6 m) only some directions keep any segment in view;
///  - the solvers get the angular velocity with an error of fixed magnitude
///    omega_error about a random axis.
/// CELC's l1 / l3 and CE3LC's l2 are fitted from each cluster's own events
/// (attachFittedLines with the given motion, as `celc run` does), never taken
/// from the ground truth.
#include <array>
#include <random>
#include <string>
#include <vector>

#include "celc/geometry/camera.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/lines/line_fit.hpp"
#include "celc/core/observations.hpp"

namespace celc {

struct PeerSceneOptions {
  int n_lines = 5;                   ///< 3D segments (clusters)
  int events_per_line = 200;         ///< events per segment (outliers included)
  double duration = 0.5;             ///< window length T [s], centred on t_ref
  double t_ref = 0.0;                ///< reference time [s]
  double speed = 2.0;                ///< V = |v| [m/s]
  double omega_deg_s = 15.0;         ///< |w| [deg/s]
  double event_noise_px = 1.0;       ///< sigma of the event pixel noise per axis [px]
  double omega_error_deg_s = 0.0;    ///< magnitude of the error of the given angular velocity [deg/s]
  double outlier_fraction = 0.0;     ///< share of events replaced by uniform random pixels [0, 1)
  /// |a| [m/s^2] of a constant acceleration in the reference frame, about a
  /// random direction: p(t) = tau v + tau^2 a / 2, so that v stays the mean
  /// velocity over the window (the truth) while the solvers assume it constant.
  double acceleration = 0.0;
  double min_separation_px = 100.0;  ///< endpoint distance at t_ref [px]
  Vec2 depth_range{2.0, 6.0};        ///< endpoint depth z [m]
  int max_attempts = 2000;           ///< segment draws per line before the motion is drawn again
  int max_motion_draws = 200;        ///< motion draws (w axis, v direction) before giving up
  /// Event pixels rounded to integers after the noise (as a DAVIS delivers them).
  bool integer_pixels = false;
  CameraModel camera = defaultCamera();
  /// The tool's line fit (its defaults: the moving model, with the given rotation).
  LineFitOptions line_fit;
  std::string validate() const;      ///< empty when valid

  static CameraModel defaultCamera();  ///< 640 x 480, f = 320 px, (cx, cy) = (320, 240)
};
/// PeerSceneOptions' scalar fields with their units and ranges
/// (core/fields.hpp); validate() checks them, the relations between them,
/// the camera and the line fit.
void describe(FieldVisitor& v, PeerSceneOptions& options);

/// One generated trial.
struct PeerSceneTrial {
  bool ok = false;                  ///< false when no segment satisfied the constraints
  std::string message;
  WindowObservations observations;  ///< noisy events, lines fitted from them
  /// The truth for the Cramér-Rao bound: the inlier events without noise, and
  /// l1 / l3 the true image lines at the window's start and end.
  WindowObservations truth;
  MotionModel true_motion = MotionModel::constantTwist(Vec3::Zero(), 0.0);
  MotionModel given_motion = MotionModel::constantTwist(Vec3::Zero(), 0.0);
  Vec3 true_direction = Vec3::Zero();  ///< unit v
  Vec3 true_omega = Vec3::Zero();      ///< [rad/s]
  Vec3 true_acceleration = Vec3::Zero();  ///< a [m/s^2], reference frame (options.acceleration)
  std::vector<std::array<Vec3, 2>> segments;  ///< endpoints [m], reference frame
  int lines_fitted = 0;             ///< clusters whose l1 and l3 could be fitted
};

/// Generates one trial; deterministic for a given rng state. Invalid options
/// give ok = false and the reason in message.
PeerSceneTrial generatePeerScene(const PeerSceneOptions& options, std::mt19937_64& rng);

}  // namespace celc
