#include "celc/geometry/camera.hpp"

#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace celc {

DistortionModel parseDistortionModel(const std::string& name) {
  if (name == "none" || name.empty()) return DistortionModel::None;
  if (name == "radtan" || name == "plumb_bob" || name == "radial-tangential")
    return DistortionModel::RadTan;
  if (name == "equidistant" || name == "fisheye") return DistortionModel::Equidistant;
  throw std::invalid_argument("unknown distortion model '" + name +
                              "' (expected none, radtan or equidistant)");
}

std::string toString(DistortionModel model) {
  switch (model) {
    case DistortionModel::None: return "none";
    case DistortionModel::RadTan: return "radtan";
    case DistortionModel::Equidistant: return "equidistant";
  }
  return "none";
}

Vec2 CameraModel::distort(const Vec2& xy) const {
  const double x = xy.x(), y = xy.y();
  switch (distortion) {
    case DistortionModel::None: return xy;
    case DistortionModel::RadTan: {
      const double k1 = coeffs[0], k2 = coeffs[1], p1 = coeffs[2], p2 = coeffs[3], k3 = coeffs[4];
      const double r2 = x * x + y * y;
      const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
      return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
              y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
    }
    case DistortionModel::Equidistant: {
      const double r = std::sqrt(x * x + y * y);
      if (r < 1e-12) return xy;
      const double th = std::atan(r), th2 = th * th;
      const double thd =
          th * (1.0 + th2 * (coeffs[0] + th2 * (coeffs[1] + th2 * (coeffs[2] + th2 * coeffs[3]))));
      return xy * (thd / r);
    }
  }
  return xy;
}

Vec2 CameraModel::undistort(const Vec2& xy_d) const {
  if (distortion == DistortionModel::None) return xy_d;
  // Gauss-Newton on distort(x) = xy_d with a numeric 2x2 Jacobian.
  Vec2 x = xy_d;
  for (int it = 0; it < 20; ++it) {
    const Vec2 r = distort(x) - xy_d;
    if (r.squaredNorm() < 1e-24) break;
    const double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (distort(x + Vec2(h, 0.0)) - distort(x - Vec2(h, 0.0))) / (2.0 * h);
    J.col(1) = (distort(x + Vec2(0.0, h)) - distort(x - Vec2(0.0, h))) / (2.0 * h);
    x -= J.partialPivLu().solve(r);
  }
  return x;
}

Vec2 CameraModel::project(const Vec3& p_cam) const {
  const Vec2 xd = distort(Vec2(p_cam.x() / p_cam.z(), p_cam.y() / p_cam.z()));
  return {fx * xd.x() + cx, fy * xd.y() + cy};
}

Vec3 CameraModel::bearing(const Vec2& pixel) const {
  const Vec2 xu = undistort(Vec2((pixel.x() - cx) / fx, (pixel.y() - cy) / fy));
  return {xu.x(), xu.y(), 1.0};
}

std::string CameraModel::validate() const { return rangeProblemsOf(*this); }

}  // namespace celc
