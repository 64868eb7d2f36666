// celc_ml: the joint refinement of v and the lines from several starts.
#include "celc_ml.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "refine.hpp"
#include "robust_nullspace.hpp"
#include "sign_test.hpp"

namespace celc::detail {

bool nptStartApplies(const WindowObservations& obs, const MotionModel& motion,
                     const MlOptions& options) {
  if (!options.second_start) return false;
  if (motion.kind() == MotionModelKind::GyroIntegrated && motion.velocityFrame() == VelocityFrame::Reference)
    return true;
  double tau = 0.0;
  for (const auto& c : obs.clusters)
    for (double t : c.times)
      if (std::isfinite(t)) tau = std::max(tau, std::abs(t - motion.referenceTime()));
  const Vec3 w = motion.meanOmega(motion.referenceTime(), motion.referenceTime() + 1.0);
  return w.norm() * tau / 2.0 <= options.second_start_max_twist;
}

SolverResult solveCelcMl(const WindowObservations& obs, const MotionModel& motion,
                         const SolverResult& linear, const SolverResult* npt,
                         const SolverOptions& options, const WindowFrames& frames,
                         std::uint64_t event_seed) {
  // The joint problem has several minima (docs/peers.md): every start is refined.
  struct Start {
    Vec3 v;
    const SolverResult* from;  // null: a lattice direction
  };
  std::vector<Start> starts;
  if (linear.ok()) starts.push_back({linear.v, &linear});
  if (npt && npt->ok()) starts.push_back({npt->v, npt});
  if (starts.empty()) return linear;  // neither start: the linear stage's status
  for (const Vec3& d : hemisphereDirections(options.ml.grid_starts)) starts.push_back({d, nullptr});
  double time_us = linear.time_us + (npt ? npt->time_us : 0.0);
  // With a lattice, the starts are screened on a subset of ml.screen_events
  // events (the basins are coarse; every start sees the same subset, so the
  // costs compare) and only the winner is refined on all of them.
  // No screening when the subset would hold every event anyway (refining the
  // winner again would repeat its work).
  size_t events = 0;
  for (const auto& c : obs.clusters)
    if (c.has_lines) events += c.size();
  const int full = options.refine.max_events;
  const bool screen = options.ml.grid_starts > 0 && options.ml.screen_events > 0 &&
                      (full == 0 || full > options.ml.screen_events) &&
                      events > static_cast<size_t>(options.ml.screen_events);
  const int start_events = screen ? options.ml.screen_events : full;
  SolverResult best;
  const SolverResult* best_from = nullptr;
  bool have = false;
  std::vector<Vec3> ends;
  for (const Start& s : starts) {
    bool seen = false;
    for (const Vec3& e : ends)
      seen = seen || angleBetweenSignAgnostic(s.v, e) * 180.0 / M_PI < options.ml.second_start_deg;
    if (seen) continue;
    SolverResult r = refineVelocity(obs, motion, s.v, true, options.refine, frames, start_events,
                                    event_seed);
    time_us += r.time_us;
    if (!r.ok()) continue;
    ends.push_back(r.v);
    if (!have || r.residual_px < best.residual_px) {
      best = r;
      best_from = s.from;
      have = true;
    }
  }
  if (!have) return linear.ok() ? linear : *npt;
  if (screen) {
    SolverResult r = refineVelocity(obs, motion, best.v, true, options.refine, frames, full, event_seed);
    time_us += r.time_us;
    if (r.ok()) best = r;
  }
  if (best_from) {
    best.sigma_min = best_from->sigma_min;
    best.sigma_second = best_from->sigma_second;
    best.sign_margin = best_from->sign_margin;
  } else {
    best.sigma_min = linear.sigma_min;
    best.sigma_second = linear.sigma_second;
    if (options.linear.resolve_sign) {
      const SignDecision sd = resolveSign(obs, motion, best.v, frames);
      best.v *= sd.sign;
      best.sign_margin = sd.margin * sd.sign;
    }
  }
  best.time_us = time_us;
  return best;
}

}  // namespace celc::detail
