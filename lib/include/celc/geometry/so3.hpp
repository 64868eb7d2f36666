#pragma once
/// \file so3.hpp
/// The rotation group SO(3): hat, exp, log and the left Jacobian.
///   hat(w) w' = w x w'
///   exp(phi) = I + sin(th)/th phi^ + (1 - cos th)/th^2 phi^^      (th = |phi|)
///   J_l(phi) = I + (1 - cos th)/th^2 phi^ + (th - sin th)/th^3 phi^^
/// J_l maps a constant body twist to the translation of the SE(3) exponential:
/// exp([v; w] tau) has translation J_l(w tau) v tau.
/// Near th = 0 the coefficients switch to their Taylor series (error < 1e-16).
#include "celc/core/types.hpp"

namespace celc::so3 {

/// Skew-symmetric matrix of w: hat(w) * u == w.cross(u).
Mat3 hat(const Vec3& w);
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
