#pragma once
/// \file crlb.hpp
/// Cramér-Rao lower bound on the velocity direction from line events under
/// Gaussian pixel noise, with the 3D lines as nuisance parameters.
///
/// Model (the maximum-likelihood problem that method celc_ml solves): per
/// cluster c the image lines l1 (time t_s) and l3 (time t_e), in the reference
/// frame m1 = R(t_s) l1, m3 = R(t_e) l3 (each unit, 2 degrees of freedom), and
/// the unit velocity direction v (2 degrees of freedom) predict the image line
/// at any time; event k's residual is its point-to-line distance in pixels
///   d_k(v, m1, m3) = focal * f'_k . l_k / |(R_k^T l_k)_{1,2}|,
///   l_k = m1 (u . v) - m3 (s . v),  u = (P_e - P_k)^T m3,  s = (P_s - P_k)^T m1,
/// and d_k ~ N(0, sigma^2) (sigma per pixel axis = sigma across the line).
/// (v, m1, m3 of all lines) <-> (direction, 3D lines) is one-to-one, so the
/// bound does not depend on this parametrisation of the lines.
/// Fisher information I = J^T J / sigma^2, J the Jacobian of all d_k w.r.t.
/// the 2 tangent coordinates of v and the 4 of each line, at the TRUE
/// parameters and the noise-free event positions. Direction block by the
/// Schur complement S = I_vv - sum_c I_vc I_cc^+ I_cv (pseudo-inverse for any
/// gauge freedom of a line); covariance bound C = S^{-1} (2 x 2, radians^2 in
/// the tangent plane), and the bound on the RMS angular error is sqrt(trace C).
#include <string>

#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"

namespace celc {

struct CrlbResult {
  bool ok = false;
  std::string message;          ///< why not ok (no events, unobservable direction, ...)
  double rms_rad = 0.0;         ///< sqrt(trace C) [rad]; +inf when the direction is unobservable
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  ///< C [rad^2], tangent basis of v
  int events = 0;               ///< events used
  int lines = 0;                ///< clusters used
};

/// `truth`: per cluster the noise-free event bearings (x, y, 1) and times, and
/// its true l1 and l3 (with their times, l3.t > l1.t). `direction`: the true
/// v (any non-zero length). sigma_px >= 0 (0 gives a zero bound).
CrlbResult velocityDirectionCrlb(const WindowObservations& truth, const MotionModel& motion,
                                 const Vec3& direction, double sigma_px);

}  // namespace celc
