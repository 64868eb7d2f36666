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
/// (tau = t - t0, relative to the centre at the time origin t0:
/// NptOptions::time_origin). The ray (f', c x f') meets the 3D line with Plücker
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
/// the form above when P(t) = s(t) I, with tau = s(t) - s(t0); the solver uses
/// s(t) = trace(P(t)) / 3.
/// GyroIntegrated with VelocityFrame::Reference: P = tau I, exact.
/// ConstantTwist (and GyroIntegrated with a body-frame velocity, the same to
/// first order): P = tau J_l(w tau) = tau (I + [w tau]_x / 2 + O(|w tau|^2));
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
  /// Unit norm, or unit moment (|m| = 1) with NptLineNormalisation::Moment.
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
  Vec3 direction = Vec3::Zero();        ///< d, unit (sign arbitrary)
  Vec3 partial_velocity = Vec3::Zero(); ///< v_perp = a x d (line's scale, sign arbitrary)
  Vec3 averaging_row = Vec3::Zero();    ///< u_z e2 - u_y e3
  double sigma_min = 0.0, sigma_second = 0.0;  ///< of the per-line rows
  int events = 0;
};

/// Solves one line's 6x6 system from its events (times [s], bearings (x, y, 1)
/// or any positive multiple, camera frame at each time), time measured from
/// t0 [s]: rows [(s(t) - s(t0)) f'^T, f'^T], m the moment about the camera
/// centre at t0. Noise-free, every t0 gives the same d and partial velocity
/// direction; with noise the unit-norm least-squares solution depends on t0.
NptLineSolution solveNptLine(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             const MotionModel& motion, const NptOptions& options, double t0);
/// The same with t0 from options.time_origin over this line's own events.
NptLineSolution solveNptLine(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             const MotionModel& motion, const NptOptions& options);

/// t0 of a window: the midpoint of its first and last finite event times
/// (Centre) or the first (FirstEvent) [s]; 0 when it has no finite time.
double nptTimeOrigin(const WindowObservations& obs, NptTimeOrigin origin);

/// The whole solver over a window's clusters (their l1/l2/l3 are not used),
/// every line's time from nptTimeOrigin(obs, options.time_origin).
/// The returned v is unit, sign arbitrary (resolve with resolveSign);
/// sigma_min / sigma_second are those of the averaging stage.
SolverResult solveNpt(const WindowObservations& obs, const MotionModel& motion,
                      const NptOptions& options);

}  // namespace celc
