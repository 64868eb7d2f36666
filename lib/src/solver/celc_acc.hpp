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
// The linear estimate: IRLS with Huber weights (options.huber_k robust
// scales, the scale from the MAD) on the geometric residuals, each step the
// weighted least squares with a eliminated (a = -M_aa^-1 M_av v, v the
// smallest eigenvector of the 3x3 Schur complement), started from CELC's
// estimate with a = 0.
//
// The linear answer alone is weak: the lines l1 / l3 are fitted under a
// motion linear in time, and v and a reach the lines at the same (second)
// order in time. The answer is the joint maximum-likelihood refinement of
// v, a and every cluster's lines (JointProblem with an acceleration: the
// lines' image motion under the constant acceleration), started from the
// linear (v, a) and from celc_ml's v with a = 0 (its lines, and the fitted
// ones); the lowest robust cost wins.
// Then two checks, each falling back to celc_ml's answer where it fails:
//   observable: at least acc.min_lines lines, and a's standard deviation
//     (Fisher information with the lines and v eliminated, the residuals'
//     robust scale) times the longest |t - t_ref| at most acc.max_sigma;
//     else Degeneracy::AccelerationUnobservable, status ok, and the message
//     says why;
//   seen: the likelihood ratio 2 (C_0 - C_a) / s^2 above acc.test_chi2, C_a
//     the accelerating end point's cost, C_0 that of celc_ml's answer
//     refined on the same events under the same loss with a = 0.
#include <cstdint>

#include "celc/solver/solver.hpp"
#include "celc_ml.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

/// celc_acc on the window's frames: `celc` is CELC's linear result (the
/// linear stage's start and sign), `ml` celc_ml's (the second start and the
/// constant-velocity answer) with its lines and Huber threshold `ml_end`
/// (when valid: the start's lines and the joint problem's loss); rows drawn with row_seed as CELC draws them,
/// the joint problem's events with event_seed as celc_ml draws them.
/// SolverResult::acceleration is a / |v| [1/s] (reference frame) and
/// acceleration_seen the test's verdict; sigma_deg is set where the
/// acceleration is seen (the Fisher information with the lines and a
/// eliminated). Its time includes celc's and celc_ml's.
SolverResult solveCelcAcc(const WindowObservations& obs, const MotionModel& motion, const SolverResult& celc,
                          const SolverResult& ml, const MlEnd& ml_end, const SolverOptions& options,
                          const WindowFrames& frames, std::uint64_t row_seed, std::uint64_t event_seed);

}  // namespace celc::detail
