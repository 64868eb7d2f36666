#pragma once
/// \file undistort.hpp
/// Per-pixel lookup table of undistorted normalised coordinates: event pixels
/// are integers, so undistortion reduces to a table read. Built with OpenCV
/// (cv::undistortPoints for radtan, cv::fisheye::undistortPoints for equidistant),
/// entry (x, y) = undistorted normalised point (X/Z, Y/Z) of pixel centre (x, y).
#include <vector>

#include "celc/geometry/camera.hpp"

namespace celc {

/// Largest sensor side [px] the table is built for: 4096 x 4096 pixels take
/// 256 MB of table, so larger sizes (from a hostile calibration or file
/// header) are refused before anything is allocated.
inline constexpr int kMaxSensorSide = 4096;

class UndistortLut {
 public:
  UndistortLut() = default;
  /// Builds the table for every pixel of camera (width x height). Throws
  /// std::invalid_argument when the camera is invalid or a side exceeds kMaxSensorSide.
  explicit UndistortLut(const CameraModel& camera);
  int width() const { return w_; }
  int height() const { return h_; }
  /// Normalised undistorted point of integer pixel (x, y); requires 0 <= x < width, 0 <= y < height.
  Vec2 at(int x, int y) const {
    const std::size_t i = 2 * (std::size_t(y) * std::size_t(w_) + std::size_t(x));
    return {xy_[i], xy_[i + 1]};
  }
  /// Bearing (x, y, 1) of a pixel; false when outside the table (out untouched).
  bool bearing(int x, int y, Vec3& out) const {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return false;
    const Vec2 p = at(x, y);
    out = Vec3(p.x(), p.y(), 1.0);
    return true;
  }

 private:
  int w_ = 0, h_ = 0;
  std::vector<double> xy_;
};

/// OpenCV undistortion of arbitrary pixels to normalised coordinates (same model as the LUT).
std::vector<Vec2> undistortPixelsCv(const CameraModel& camera, const std::vector<Vec2>& pixels);

}  // namespace celc
