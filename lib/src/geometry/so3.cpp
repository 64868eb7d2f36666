#include "celc/geometry/so3.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace celc::so3 {

Vec3 vee(const Mat3& W) { return Vec3(W(2, 1), W(0, 2), W(1, 0)); }

void coefficients(double x, double& A, double& B, double& C) {
  if (x < 0.1) {
    // Seven terms (the next is below 1e-20 relative, x^7 / 16!), as even and
    // odd polynomials in y = x^2: four short chains instead of two long ones.
    const double y = x * x;
    const double b_even = 1.0 / 2 + y * (1.0 / 720 + y * (1.0 / 3628800 + y * (1.0 / 87178291200.0)));
    const double b_odd = 1.0 / 24 + y * (1.0 / 40320 + y * (1.0 / 479001600));
    const double c_even = 1.0 / 6 + y * (1.0 / 5040 + y * (1.0 / 39916800 + y * (1.0 / 1307674368000.0)));
    const double c_odd = 1.0 / 120 + y * (1.0 / 362880 + y * (1.0 / 6227020800.0));
    B = b_even - x * b_odd;
    C = c_even - x * c_odd;
    A = 1.0 - x * C;
    return;
  }
  if (x < kSeriesLimit) return seriesCoefficients(x, A, B, C);
  const double th = std::sqrt(x);
  const double s = std::sin(th), sh = std::sin(0.5 * th) / th;
  // 1 - cos th = 2 sin^2(th/2).
  A = s / th, B = 2.0 * sh * sh, C = (th - s) / (x * th);
}

Mat3 exp(const Vec3& phi) {
  double a, b, c;
  coefficients(phi.squaredNorm(), a, b, c);
  const Mat3 W = hat(phi);
  return Mat3::Identity() + a * W + b * W * W;
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
  double a, b, c;
  coefficients(phi.squaredNorm(), a, b, c);
  const Mat3 W = hat(phi);
  return Mat3::Identity() + b * W + c * W * W;
}

void expAndLeftJacobian(const Vec3& phi, Mat3& R, Mat3& J) {
  double a, b, c;
  coefficients(phi.squaredNorm(), a, b, c);
  const Mat3 W = hat(phi);
  const Mat3 W2 = W * W;
  R = Mat3::Identity() + a * W + b * W2;
  J = Mat3::Identity() + b * W + c * W2;
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
