#pragma once
// Internal: celc_ml's search for a constant offset of the given angular
// velocity (a gyroscope bias), option ml.rate_offset.
//
// The joint cost concentrated on the offset delta [rad/s, camera frame]:
//   C(delta) = min over v and every cluster's lines of the joint Huber cost
//              (joint_refine.hpp) with R(t), P(t) from
//              motion.withOmegaOffset(delta),
// each value one joint refinement to convergence from the fitted lines and
// the v of the lowest value so far. C is minimised by Nelder-Mead from
// delta = 0 (C is not convex in delta: a Newton step on a quadratic model
// was measured to fail in half of the trials, docs/accuracy.md). The offset is
// kept when the likelihood ratio
//   LR = 2 (C(0) - C(delta)) / sigma^2,  sigma^2 = 2 C(0) / N
// (N events) exceeds kRateOffsetGate: without an offset LR follows a
// chi-square law with 3 degrees of freedom, and the gate is its p = 0.001
// quantile.
#include <cstdint>

#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"
#include "celc/solver/solver.hpp"

namespace celc::detail {

/// chi-square, 3 degrees of freedom, p = 0.001.
constexpr double kRateOffsetGate = 16.27;

struct RateOffsetFit {
  bool accepted = false;    ///< LR above kRateOffsetGate
  Vec3 delta = Vec3::Zero();  ///< the minimiser [rad/s] (whether accepted or not)
  Vec3 v = Vec3::Zero();    ///< v at the minimiser (unit, sign as refined)
  double likelihood_ratio = 0.0;
  int evaluations = 0;      ///< joint refinements
};

/// The search above from v (unit) on the joint problem's events (ml.max_events,
/// drawn with event_seed) under a Huber threshold of huber_px [px].
RateOffsetFit searchRateOffset(const WindowObservations& obs, const MotionModel& motion, const Vec3& v,
                               const SolverOptions& options, std::uint64_t event_seed, double huber_px);

}  // namespace celc::detail
