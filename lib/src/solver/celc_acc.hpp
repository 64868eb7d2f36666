#pragma once
// Internal: CELC with a constant acceleration (Method::CelcAcc).
//
// The camera's position over the window, reference frame,
//   p(t) = P(t) v + q(t) a,   q(t) = (t - t_ref)^2 / 2,
// with P(t) the motion model's (constant velocity v, body or reference frame
// as the model says) and a a constant reference-frame acceleration beyond it.
// A cluster's transferred line at an event's time t_k is then
//   l = B_v v + B_a a,   B_v = m1 u^T - m3 s^T (celc_residual.hpp),
//   B_a = (q_e - q_k) m1 m3^T - (q_s - q_k) m3 m1^T,
// so the event's residual (R_k f)^T l / |(R_k^T l)_xy| stays linear in
// x = (v, a) up to its normaliser: one 6-vector row per event, the same
// rows as CELC's for a = 0. v and a share one unknown scale; |v| = 1 fixes it.
//
// The estimate: IRLS with Huber weights (options.huber_k robust scales, the
// scale from the MAD) on the geometric residuals, each step the weighted
// least squares with a eliminated (a = -M_aa^-1 M_av v, v the smallest
// eigenvector of the 3x3 Schur complement), started from CELC's estimate
// with a = 0; v's sign is CELC's (resolved by cheirality). Whether the
// acceleration is seen is an F-test of the cost with a against the cost of
// the best a = 0 (3 added unknowns, p = 0.001).
#include <cstdint>

#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

/// celc_acc on the window's frames: `celc` is CELC's linear result (the
/// start and the sign); rows drawn with row_seed as CELC draws them.
/// SolverResult::acceleration is a / |v| [1/s] (reference frame) and
/// acceleration_seen the F-test's verdict; sigma_deg is set from the
/// weighted system (the residual scale over the Schur complement's curvature).
SolverResult solveCelcAcc(const WindowObservations& obs, const MotionModel& motion, const SolverResult& celc,
                          const LinearOptions& options, const WindowFrames& frames, std::uint64_t row_seed);

}  // namespace celc::detail
