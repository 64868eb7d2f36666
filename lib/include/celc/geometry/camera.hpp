#pragma once
/// \file camera.hpp
/// Pinhole camera with an optional lens distortion, in OpenCV's conventions:
/// pixel u = fx * xd + cx, v = fy * yd + cy, where (xd, yd) is the distorted
/// normalised point of the undistorted one (x, y) = (X/Z, Y/Z).
///  - RadTan (plumb-bob): k1 k2 p1 p2 k3, as cv::projectPoints.
///  - Equidistant (Kannala-Brandt, cv::fisheye): k1 k2 k3 k4,
///    theta_d = theta (1 + k1 th^2 + k2 th^4 + k3 th^6 + k4 th^8), theta = atan(r).
#include <array>
#include <string>

#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc {

enum class DistortionModel { None, RadTan, Equidistant };

/// Parses "none" / "radtan" (also "plumb_bob") / "equidistant" (also "fisheye").
DistortionModel parseDistortionModel(const std::string& name);
std::string toString(DistortionModel model);

struct CameraModel {
  int width = 346;   ///< [px]
  int height = 260;  ///< [px]
  double fx = 320.0, fy = 320.0;  ///< focal lengths [px]
  double cx = 173.0, cy = 130.0;  ///< principal point [px]
  DistortionModel distortion = DistortionModel::None;
  /// RadTan: {k1, k2, p1, p2, k3}; Equidistant: {k1, k2, k3, k4, unused}.
  std::array<double, 5> coeffs{0.0, 0.0, 0.0, 0.0, 0.0};

  /// Undistorted normalised point -> distorted normalised point.
  Vec2 distort(const Vec2& xy) const;
  /// Distorted normalised point -> undistorted normalised point (Newton / fixed point, 20 iterations max).
  Vec2 undistort(const Vec2& xy_d) const;
  /// Camera-frame point (Z > 0) -> pixel.
  Vec2 project(const Vec3& p_cam) const;
  /// Pixel -> bearing (x, y, 1) in undistorted normalised coordinates.
  Vec3 bearing(const Vec2& pixel) const;
  /// Mean focal length [px], to convert normalised distances to pixels.
  double focal() const { return 0.5 * (fx + fy); }
  bool inImage(const Vec2& pixel) const {
    return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < width && pixel.y() < height;
  }
  /// Empty when valid, else what is wrong.
  std::string validate() const;
};
/// The schema of a camera: size, intrinsics, distortion (core/fields.hpp).
void describe(FieldVisitor& v, CameraModel& camera);


}  // namespace celc
