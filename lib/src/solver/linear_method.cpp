// The steps the linear methods share: input checks and the nullspace's result.
#include "linear_method.hpp"

#include <cmath>
#include <utility>

#include "sign_test.hpp"

namespace celc::detail {

SolverResult failure(SolveStatus status, Degeneracy reason, std::string message) {
  SolverResult r;
  r.status = status;
  r.degeneracy = reason;
  r.message = std::move(message);
  return r;
}

bool rejectInput(const WindowObservations& obs, const MotionModel& motion,
                 const LinearOptions& opt, SolverResult& r) {
  if (const std::string err = opt.validate(); !err.empty()) {
    r = failure(SolveStatus::InvalidInput, Degeneracy::None, "options: " + err);
    return true;
  }
  if (!(obs.focal_px > 0.0) || !std::isfinite(obs.focal_px)) {
    r = failure(SolveStatus::InvalidInput, Degeneracy::None, "focal length must be positive");
    return true;
  }
  if (!motion.rotation(motion.referenceTime()).allFinite()) {
    r = failure(SolveStatus::InvalidInput, Degeneracy::None, "angular velocity is not finite");
    return true;
  }
  return false;
}

double impliedNullspaceSigmaDeg(double sigma_min, double sigma_second, int rows) {
  if (!(sigma_second > 0.0)) return HUGE_VAL;
  const double ratio = sigma_min / sigma_second;
  const double gap = rows * (1.0 / (ratio * ratio) - 1.0);
  return gap > 0.0 ? 180.0 / M_PI / std::sqrt(gap) : HUGE_VAL;
}

SolverResult nullspaceResult(const NullspaceSolution& ns, const WindowObservations& obs,
                             const MotionModel& motion, const LinearOptions& opt, int rows,
                             const WindowFrames& frames) {
  if (!ns.ok) return failure(SolveStatus::Failed, Degeneracy::None, "robust nullspace did not converge");
  SolverResult r;
  r.sigma_min = ns.sigma_min;
  r.sigma_second = ns.sigma_second;
  r.iterations = ns.iterations;
  r.rows_used = rows;
  r.residual_px = ns.scale * obs.focal_px;
  const double ratio = ns.sigma_second > 0.0 ? ns.sigma_min / ns.sigma_second : 1.0;
  const double implied_deg = impliedNullspaceSigmaDeg(ns.sigma_min, ns.sigma_second, rows);
  if (!(implied_deg <= opt.max_nullspace_sigma_deg)) {
    r.status = SolveStatus::Degenerate;
    r.degeneracy = Degeneracy::NullspaceNotUnique;
    r.message = "two smallest singular values too close (ratio " + std::to_string(ratio) + " over " +
                std::to_string(rows) + " rows: direction std about " + std::to_string(implied_deg) + " deg)";
    if (ns.v.allFinite() && ns.v.norm() > 0.0) r.v = ns.v.normalized();
    return r;
  }
  r.v = ns.v.normalized();
  if (opt.resolve_sign) {
    const SignDecision s = resolveSign(obs, motion, r.v, frames);
    r.v *= s.sign;
    r.sign_margin = s.margin * s.sign;
  }
  r.status = SolveStatus::Ok;
  return r;
}

}  // namespace celc::detail
