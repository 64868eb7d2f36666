#include "celc/geometry/so3.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace celc::so3 {

Mat3 hat(const Vec3& w) {
  Mat3 W;
  W << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return W;
}

Vec3 vee(const Mat3& W) { return Vec3(W(2, 1), W(0, 2), W(1, 0)); }

namespace {
// Coefficients a = sin(th)/th, b = (1-cos th)/th^2, c = (th - sin th)/th^3,
// with Taylor series below a small angle where the closed forms lose digits.
struct Coeffs {
  double a, b, c;
};
Coeffs coefficients(double th2) {
  if (th2 < 1e-6) {
    // Series to the th^4 term: errors below 1e-19 for th^2 < 1e-6.
    return {1.0 - th2 / 6.0 + th2 * th2 / 120.0,  //
            0.5 - th2 / 24.0 + th2 * th2 / 720.0,  //
            1.0 / 6.0 - th2 / 120.0 + th2 * th2 / 5040.0};
  }
  const double th = std::sqrt(th2);
  const double s = std::sin(th), sh = std::sin(0.5 * th) / th;
  // 1 - cos th = 2 sin^2(th/2): no cancellation at small angles.
  return {s / th, 2.0 * sh * sh, (th - s) / (th2 * th)};
}
}  // namespace

Mat3 exp(const Vec3& phi) {
  const Coeffs k = coefficients(phi.squaredNorm());
  const Mat3 W = hat(phi);
  return Mat3::Identity() + k.a * W + k.b * W * W;
}

Vec3 log(const Mat3& R) {
  // Quaternion route: stable for all angles including pi.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() *= -1.0;
  const Vec3 u = q.vec();
  const double sn = u.norm();
  if (sn < 1e-12) return 2.0 * u;  // th ~ 2 |u| near identity
  const double th = 2.0 * std::atan2(sn, q.w());
  return (th / sn) * u;
}

Mat3 leftJacobian(const Vec3& phi) {
  const Coeffs k = coefficients(phi.squaredNorm());
  const Mat3 W = hat(phi);
  return Mat3::Identity() + k.b * W + k.c * W * W;
}

void expAndLeftJacobian(const Vec3& phi, Mat3& R, Mat3& J) {
  const Coeffs k = coefficients(phi.squaredNorm());
  const Mat3 W = hat(phi);
  const Mat3 W2 = W * W;
  R = Mat3::Identity() + k.a * W + k.b * W2;
  J = Mat3::Identity() + k.b * W + k.c * W2;
}

Mat3 leftJacobianInverse(const Vec3& phi) {
  const double th2 = phi.squaredNorm();
  const Mat3 W = hat(phi);
  double d;  // (1/th^2) (1 - (th/2) cot(th/2)), series near 0
  if (th2 < 1e-6) {
    d = 1.0 / 12.0 + th2 / 720.0 + th2 * th2 / 30240.0;
  } else {
    const double th = std::sqrt(th2);
    d = (1.0 - 0.5 * th * std::cos(0.5 * th) / std::sin(0.5 * th)) / th2;
  }
  return Mat3::Identity() - 0.5 * W + d * W * W;
}

}  // namespace celc::so3
