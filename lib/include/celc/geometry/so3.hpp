#pragma once
/// \file so3.hpp
/// The rotation group SO(3): hat, exp, log and the left Jacobian.
///   hat(w) w' = w x w'
///   exp(phi) = I + sin(th)/th phi^ + (1 - cos th)/th^2 phi^^      (th = |phi|)
///   J_l(phi) = I + (1 - cos th)/th^2 phi^ + (th - sin th)/th^3 phi^^
/// J_l maps a constant body twist to the translation of the SE(3) exponential:
/// exp([v; w] tau) has translation J_l(w tau) v tau.
/// Up to th = 1.5 rad the coefficients are their Taylor series (no sin, no
/// cancellation); beyond, the closed forms.
#include "celc/core/types.hpp"

namespace celc::so3 {

/// th^2 below which seriesCoefficients is used (th <= 1.5 rad).
constexpr double kSeriesLimit = 2.25;

/// A = sin th / th, B = (1 - cos th) / th^2 and C = (th - sin th) / th^3 by
/// their Taylor series in x = th^2 <= kSeriesLimit, to the x^10 term
/// (truncation below 1e-19 relative); A = 1 - x C. Inline, so that kernels
/// evaluate it across events.
inline void seriesCoefficients(double x, double& A, double& B, double& C) {
  // 1 / (2k + 2)! and 1 / (2k + 3)!, k = 0..10.
  constexpr double kB[11] = {1.0 / 2, 1.0 / 24, 1.0 / 720, 1.0 / 40320, 1.0 / 3628800,
                             1.0 / 479001600, 1.0 / 87178291200.0, 1.0 / 20922789888000.0,
                             1.0 / 6402373705728000.0, 1.0 / 2432902008176640000.0,
                             1.0 / 1124000727777607680000.0};
  constexpr double kC[11] = {1.0 / 6, 1.0 / 120, 1.0 / 5040, 1.0 / 362880, 1.0 / 39916800,
                             1.0 / 6227020800.0, 1.0 / 1307674368000.0, 1.0 / 355687428096000.0,
                             1.0 / 121645100408832000.0, 1.0 / 51090942171709440000.0,
                             1.0 / 25852016738884976640000.0};
  B = kB[10], C = kC[10];
  for (int k = 9; k >= 0; --k) B = kB[k] - x * B, C = kC[k] - x * C;
  A = 1.0 - x * C;
}

/// A, B, C as above for any x = th^2 >= 0: the series below kSeriesLimit (to
/// the x^6 term below x = 0.1), else sin th / th, 2 sin^2(th / 2) / th^2 and
/// (th - sin th) / th^3.
void coefficients(double x, double& A, double& B, double& C);

/// Skew-symmetric matrix of w: hat(w) * u == w.cross(u). Inline: exp and
/// the Jacobians build one per event and pose.
inline Mat3 hat(const Vec3& w) {
  Mat3 W;
  W << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return W;
}
/// Inverse of hat for a skew-symmetric matrix.
Vec3 vee(const Mat3& W);
/// Rotation matrix exp(hat(phi)); phi is an axis-angle vector [rad].
Mat3 exp(const Vec3& phi);
/// Axis-angle vector of R, |log(R)| in [0, pi].
Vec3 log(const Mat3& R);
/// Left Jacobian J_l(phi) of SO(3).
Mat3 leftJacobian(const Vec3& phi);
/// exp(phi) and J_l(phi) together, sharing one sin/cos.
void expAndLeftJacobian(const Vec3& phi, Mat3& R, Mat3& J);
/// Inverse of the left Jacobian.
Mat3 leftJacobianInverse(const Vec3& phi);

}  // namespace celc::so3
