#pragma once
/// \file metrics.hpp
/// The paper's errors of an estimated velocity direction, in one place for the
/// run tables, the simulation study and the peer study. On unit vectors:
///   eps = |v_gt - v_est|,
///   phi = angle between v_gt and v_est in [0, pi] [rad] (acos(v_gt . v_est),
///         computed in a form accurate for small and large angles alike),
///   sign-agnostic phi = min(phi, pi - phi), for methods that do not resolve
///         the sign of v.
#include "celc/core/types.hpp"

namespace celc {

/// eps = |truth - estimate|.
double directionDistance(const Vec3& truth, const Vec3& estimate);
/// phi: the angle between truth and estimate [rad], in [0, pi].
double directionAngle(const Vec3& truth, const Vec3& estimate);
/// min(phi, pi - phi) [rad]: the angle when the sign does not count.
double signAgnosticAngle(double phi);

/// All three errors of one estimate.
struct DirectionErrors {
  double eps = 0.0;
  double phi = 0.0;                ///< [rad]
  double phi_sign_agnostic = 0.0;  ///< [rad]
};
DirectionErrors directionErrors(const Vec3& truth, const Vec3& estimate);

}  // namespace celc
