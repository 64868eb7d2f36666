#pragma once
/// \file types.hpp
/// Conventions shared by every module (also stated in README.md):
///  - time: double seconds inside the library, int64 microseconds only inside
///    binary formats; windows are half-open [t0, t1);
///  - pixels: origin top-left, x right, y down;
///  - normalised (undistorted) image coordinates: bearing (x, y, 1);
///  - camera frame: x right, y down, z forward (OpenCV);
///  - angles in radians, angular velocity in rad/s, linear velocity in m/s.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace celc {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// One event: time [s], pixel (x right, y down, origin top-left), polarity.
struct Event {
  double t = 0.0;
  float x = 0.0f;
  float y = 0.0f;
  bool on = true;
};

/// One IMU sample in the IMU's own frame: gyro [rad/s], accel [m/s^2].
struct ImuSample {
  double t = 0.0;
  Vec3 gyro = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
};

/// A ground-truth pose T_world_body at time t [s].
struct PoseSample {
  double t = 0.0;
  Vec3 position = Vec3::Zero();                 ///< p_world_body [m]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< R_world_body
};

}  // namespace celc
