#pragma once
/// \file npt.hpp
/// The N-point linear solver with velocity averaging of Gao, Su, Gehrig,
/// Cannici, Scaramuzza and Kneip, "An N-point linear solver for line and motion
/// estimation with event cameras", CVPR 2024, written from its published
/// mathematics (method `npt`).
///
/// Known rotation, constant linear velocity v in the reference frame. An event
/// at time t with unit bearing f (camera frame at t), rotated into the
/// reference frame, f' = R(t) f, was seen from the camera centre c = tau v
/// (tau = t - t_ref). The ray (f', c x f') meets the 3D line with Plücker
/// coordinates (d, m) (unit direction d, moment m = X x d) iff
///   d . (c x f') + m . f' = 0   <=>   tau f'^T (d x v) + f'^T m = 0,
/// linear and homogeneous in x = [d x v; m] (6 unknowns): one row
/// [tau f'^T, f'^T] per event, x = smallest right singular vector of the
/// cluster's rows (>= 5 events). From x = [a; m]: d = (m x a)/|m x a| (d is
/// orthogonal to both), the partial velocity v_perp = a x d (the component of
/// v orthogonal to d, up to the line's unknown scale).
/// Velocity averaging: per line the frame e1 = d, e2 = -m/|m|, e3 = e1 x e2,
/// (0, u_y, u_z) = v_perp in that frame; v is orthogonal to e1 x v_perp, i.e.
/// (u_z e2 - u_y e3)^T v = 0; v = smallest right singular vector of the
/// stacked rows. The sign of v is not observable by this solver.
///
/// General motion models: the incidence holds with c = P(t) v. It is exactly
/// the form above when P(t) = s(t) I; the solver uses s(t) = trace(P(t)) / 3.
/// GyroIntegrated (velocity constant in the reference frame): P = tau I, exact.
/// ConstantTwist: P = tau J_l(w tau) = tau (I + [w tau]_x / 2 + O(|w tau|^2));
/// trace/3 keeps the symmetric part (error O(|w tau|^2)) and drops the skew
/// part, a relative error of up to |w| |tau| / 2 on the camera displacement
/// (1.9% at 15 deg/s and |tau| = 0.25 s): the solver's own model, documented.
#include <string>
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/solver/solver.hpp"

namespace celc {

// NptOptions is declared in solver.hpp (part of SolverOptions).


/// Per-line stage: x = [d x v; m] up to scale and sign, and what follows from it.
struct NptLineSolution {
  bool ok = false;
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();  ///< unit norm
  Vec3 direction = Vec3::Zero();        ///< d, unit (sign arbitrary)
  Vec3 partial_velocity = Vec3::Zero(); ///< v_perp = a x d (line's scale, sign arbitrary)
  Vec3 averaging_row = Vec3::Zero();    ///< u_z e2 - u_y e3
  double sigma_min = 0.0, sigma_second = 0.0;  ///< of the per-line rows
  int events = 0;
};

/// Solves one line's 6x6 system from its events (times [s], bearings (x, y, 1)
/// or any positive multiple, camera frame at each time).
NptLineSolution solveNptLine(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             const MotionModel& motion, const NptOptions& options);

/// The whole solver over a window's clusters (their l1/l2/l3 are not used).
/// The returned v is unit, sign arbitrary (resolve with resolveSign);
/// sigma_min / sigma_second are those of the averaging stage.
SolverResult solveNpt(const WindowObservations& obs, const MotionModel& motion,
                      const NptOptions& options);

}  // namespace celc
