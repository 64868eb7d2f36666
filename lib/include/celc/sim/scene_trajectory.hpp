#pragma once
/// \file scene_trajectory.hpp
/// Camera trajectories of the rendering simulator, as T_world_cam(t).
///
/// The motion is a body twist (v(t), w(t)) in the camera frame (v [m/s],
/// w [rad/s]); over an interval where it is constant the pose moves as
/// MotionModel::constantTwist: relative to the pose at t_ref,
///   R = exp(w^ tau),  p = J_l(w tau) v tau,  tau = t - t_ref.
/// Kinds:
///  - constant twist: one (v, w) for all t (also t < 0);
///  - piecewise: consecutive segments of constant twist, each with a duration;
///    the last one continues after its end, the first one before 0;
///  - sinusoid: v(t) = v + A_v sin(2 pi f t), w(t) = w + A_w sin(2 pi f t),
///    integrated with the midpoint rule on a 0.1 ms grid (horizons up to 20 s;
///    coarser beyond, at most 2e5 knots);
///  - constant acceleration: a constant w and a constant acceleration a
///    [m/s^2] fixed in the world (given in the camera frame at t = 0):
///    R = R0 exp(w^ t), p = p0 + R0 (v t + a t^2 / 2), so the camera-frame
///    velocity is exp(w^ t)^T (v + a t); exact, for all t.
#include <string>
#include <vector>

#include "celc/sim/scene.hpp"

namespace celc {

enum class TrajectoryKind { ConstantTwist, Piecewise, Sinusoid, ConstantAcceleration };
/// "constant_twist" | "piecewise" | "sinusoid" | "constant_acceleration"; throws std::invalid_argument otherwise.
TrajectoryKind parseTrajectoryKind(const std::string& name);
std::string toString(TrajectoryKind kind);

struct TwistSegment {
  double duration = 1.0;  ///< [s]
  Vec3 v = Vec3::Zero();  ///< [m/s], camera frame
  Vec3 w = Vec3::Zero();  ///< [rad/s], camera frame
};

struct TrajectorySpec {
  TrajectoryKind kind = TrajectoryKind::ConstantTwist;
  Vec3 v = Vec3(1.0, 0.0, 0.0);        ///< [m/s] (constant twist; sinusoid mean)
  Vec3 w = Vec3::Zero();               ///< [rad/s]
  std::vector<TwistSegment> segments;  ///< piecewise
  Vec3 amplitude_v = Vec3::Zero();     ///< sinusoid [m/s]
  Vec3 amplitude_w = Vec3::Zero();     ///< sinusoid [rad/s]
  double frequency = 1.0;              ///< sinusoid [Hz]
  Vec3 acceleration = Vec3::Zero();    ///< constant acceleration [m/s^2], camera frame at t = 0
  RigidPose initial;                   ///< T_world_cam(0)
  std::string validate() const;        ///< empty when valid
};

class Trajectory {
 public:
  /// `horizon` [s]: the sinusoid is integrated over [0, horizon] (constant twist afterwards).
  Trajectory(const TrajectorySpec& spec, double horizon);
  const TrajectorySpec& spec() const { return spec_; }
  RigidPose pose(double t) const;           ///< T_world_cam(t)
  Vec3 linearVelocity(double t) const;      ///< v(t), camera frame [m/s]
  Vec3 angularVelocity(double t) const;     ///< w(t), camera frame [rad/s]
  Vec3 linearVelocityRate(double t) const;  ///< dv/dt, camera frame [m/s^2]
  /// Piecewise: the first segment start after t (the twist jumps there); else +infinity.
  double nextBreak(double t) const;
  /// A time over which the twist changes little: 0.01 / frequency for the
  /// sinusoid, 0.01 |v| / |a| (|v| at least 0.05 m/s) for a constant
  /// acceleration, +infinity otherwise [s].
  double smoothTime() const;

 private:
  TrajectorySpec spec_;
  std::vector<double> seg_start_;    ///< piecewise: start time of each segment
  std::vector<RigidPose> seg_pose_;  ///< pose at each segment start
  double knot_dt_ = 1e-4;
  std::vector<RigidPose> knots_;  ///< sinusoid: pose at k * knot_dt_
  int segmentAt(double t) const;
};

/// Pose after moving with constant twist (v, w) for tau seconds from identity.
RigidPose twistExp(const Vec3& v, const Vec3& w, double tau);

}  // namespace celc
