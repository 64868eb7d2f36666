// celc_ml: the joint refinement of v and the lines from several starts.
#include "celc_ml.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "joint_refine.hpp"
#include "ml_screen.hpp"
#include "rate_offset.hpp"
#include "refine.hpp"
#include "robust_nullspace.hpp"
#include "sign_test.hpp"

namespace celc::detail {

namespace {
// The profile's minima only need to land in the joint cost's basin: the
// descent stops at this step [deg].
constexpr double kProfileToleranceDeg = 0.5;
// A start this close to an earlier start's end point [deg], in v and in
// every line normal, stops: it would end there.
constexpr double kMergeDeg = 1.0;
}  // namespace

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
                         std::uint64_t event_seed, MlEnd* end) {
  if (end) *end = MlEnd{};
  // The joint problem has several minima (docs/accuracy.md): every start is refined.
  struct Start {
    Vec3 v;
    const SolverResult* from;  // null: a direction of the profile or the lattice
  };
  std::vector<Start> starts;
  if (linear.ok()) starts.push_back({linear.v, &linear});
  // An ambiguous nullspace still points into a valley of the cost.
  else if (linear.degeneracy == Degeneracy::NullspaceNotUnique && linear.v.norm() > 0.5)
    starts.push_back({linear.v, nullptr});
  if (npt && npt->ok()) starts.push_back({npt->v, npt});
  const auto t0 = std::chrono::steady_clock::now();
  // The profile's minima need no linear estimate: a window whose linear
  // stage found its nullspace ambiguous (two near-equal singular values) is
  // still answered from them.
  if (options.ml.profile_lattice > 0) {
    const LineProfile profile(obs, motion, frames.clusters(), options.ml.profile_events, event_seed);
    for (const ScreenMinimum& m : screenProfile(profile, options.ml.profile_lattice,
                                                options.ml.profile_starts, kProfileToleranceDeg,
                                                options.ml.second_start_deg))
      starts.push_back({m.v, nullptr});
  }
  if (starts.empty()) return linear;  // no start at all: the linear stage's status
  // Without a refined start: the linear estimate, npt's, or the linear status.
  auto fallback = [&]() -> SolverResult { return linear.ok() || !npt || !npt->ok() ? linear : *npt; };
  for (const Vec3& d : hemisphereDirections(options.ml.grid_starts)) starts.push_back({d, nullptr});
  const double time_us = linear.time_us + (npt ? npt->time_us : 0.0);
  JointProblem problem(obs, motion, frames, options.ml.max_events, options.refine.balance_clusters,
                       event_seed, options.refine.huber_px);
  const size_t events = problem.events();
  if (events < 3) return fallback();
  // With several starts, each is refined on every stride-th event (the
  // basins are coarse; every start sees the same events, so the costs
  // compare) and only the winner on all of them, from its end point.
  const int stride = starts.size() > 1 && options.ml.screen_events > 0 &&
                             events > static_cast<size_t>(options.ml.screen_events)
                         ? static_cast<int>((events + options.ml.screen_events - 1) /
                                            static_cast<size_t>(options.ml.screen_events))
                         : 1;
  const int iterations = options.refine.max_iterations;
  const double tolerance = options.refine.function_tolerance;
  const int start_iterations =
      starts.size() > 1 && options.ml.start_iterations > 0 ? std::min(options.ml.start_iterations, iterations)
                                                           : iterations;
  // The refined starts' end points, with their costs (all on the screen's events).
  struct End {
    JointProblem::Result result;
    const Start* start;
  };
  std::vector<End> screened;
  std::vector<JointProblem::State> ends;
  for (const Start& s : starts) {
    bool seen = false;
    for (const JointProblem::State& e : ends)
      seen = seen || angleBetweenSignAgnostic(s.v, e.v) * 180.0 / M_PI < options.ml.second_start_deg;
    if (seen) continue;
    // Every start begins at the fitted lines (measured: the profile's own
    // lines for its minima did worse at parallax 0.125, RMS 6.2 -> 10.1 deg).
    // A start that comes within kMergeDeg of an earlier end point, in v and
    // in every line, would follow its descent and stops there (docs/accuracy.md).
    JointProblem::Result r = problem.refine(problem.start(s.v), start_iterations, tolerance, stride,
                                            ends, kMergeDeg * M_PI / 180.0);
    if (!r.ok || r.merged) continue;
    if (options.ml.huber_scale > 0.0 && ends.empty()) {
      // The first end point's residuals give the noise's scale; the Huber
      // threshold becomes ml.huber_scale times it, never below
      // refine.huber_px, for every start.
      const double scaled = options.ml.huber_scale * problem.robustScale(r.state);
      if (scaled > options.refine.huber_px) {
        problem.setHuber(scaled);
        JointProblem::Result again = problem.refine(r.state, start_iterations, tolerance, stride);
        if (!again.ok) continue;
        r = std::move(again);
      }
    }
    ends.push_back(r.state);
    screened.push_back({std::move(r), &s});
  }
  if (screened.empty()) return fallback();
  std::stable_sort(screened.begin(), screened.end(),
                   [](const End& a, const End& b) { return a.result.cost < b.result.cost; });
  // ml.cheiral_tie: among end points tied in cost with the lowest, the one
  // whose clusters agree best on the cheirality sign; returns its index and,
  // when that is not the lowest, says so in `tie_note`.
  // How far r's cost lies above low_cost, N (C - C_low) / C_low (the tie's units).
  auto unitsAbove = [](const JointProblem::Result& r, double low_cost) {
    return r.events * (r.cost - low_cost) / std::max(low_cost, 1e-300);
  };
  std::string tie_note;
  auto cheiralChoice = [&](const std::vector<const JointProblem::Result*>& by_cost) -> size_t {
    if (!(options.ml.cheiral_tie > 0.0) || by_cost.size() < 2) return 0;
    tie_note.clear();  // the last choice made is the one that stands
    const JointProblem::Result& low = *by_cost.front();
    auto tied = [&](const JointProblem::Result& r) { return unitsAbove(r, low.cost) <= options.ml.cheiral_tie; };
    if (!tied(*by_cost[1])) return 0;  // no tie: no sign test
    size_t chosen = 0;
    const double low_margin = std::abs(resolveSign(obs, motion, low.state.v, frames).margin);
    double best_margin = low_margin;
    for (size_t i = 1; i < by_cost.size(); ++i) {
      const JointProblem::Result& r = *by_cost[i];
      if (!tied(r)) break;
      const double margin = std::abs(resolveSign(obs, motion, r.state.v, frames).margin);
      if (margin > best_margin + 1e-9) {
        best_margin = margin;
        chosen = i;
      }
    }
    if (chosen > 0) {
      const JointProblem::Result& r = *by_cost[chosen];
      char text[200];
      std::snprintf(text, sizeof text,
                    "basin chosen by cheirality: sign margin %.2f against %.2f at the lowest cost, %.2f units "
                    "above it (%.1f deg away)",
                    best_margin, low_margin, unitsAbove(r, low.cost),
                    angleBetweenSignAgnostic(r.state.v, low.state.v) * 180.0 / M_PI);
      tie_note = text;
    }
    return chosen;
  };
  {
    std::vector<const JointProblem::Result*> by_cost;
    for (const End& e : screened) by_cost.push_back(&e.result);
    const size_t c = cheiralChoice(by_cost);
    if (c > 0) std::rotate(screened.begin(), screened.begin() + static_cast<std::ptrdiff_t>(c),
                           screened.begin() + static_cast<std::ptrdiff_t>(c) + 1);
  }
  JointProblem::Result best = screened.front().result;
  const Start* best_start = screened.front().start;
  if (stride > 1 || start_iterations < iterations) {
    // The screen ranks its end points after a few iterations on a subset,
    // and near-tied basins can swap places on convergence: the
    // ml.finalists lowest are refined on every event of the problem and the
    // lowest converged cost wins (docs/method.md, "celc_ml's finalists").
    // The first runs to convergence; a later one runs start_iterations and
    // continues only while it is below the best so far, and one heading
    // into a basin an earlier finalist ended in stops there.
    std::vector<JointProblem::State> converged;
    std::vector<std::pair<JointProblem::Result, const Start*>> finals;
    bool have = false;
    const double merge_rad = kMergeDeg * M_PI / 180.0;
    const size_t finalists = static_cast<size_t>(std::max(1, options.ml.finalists));
    for (size_t i = 0; i < screened.size() && i < finalists; ++i) {
      JointProblem::Result r = problem.refine(screened[i].result.state, have ? start_iterations : iterations,
                                              tolerance, 1, converged, merge_rad);
      // A later finalist goes on only while within the tie of the best (below it, with no tie).
      if (!r.ok || r.merged || (have && unitsAbove(r, best.cost) >= options.ml.cheiral_tie)) continue;
      if (have && r.iterations == start_iterations && start_iterations < iterations) {
        JointProblem::Result rest = problem.refine(r.state, iterations, tolerance, 1, converged, merge_rad);
        if (!rest.ok || rest.merged) continue;
        rest.iterations += r.iterations;
        r = std::move(rest);
      }
      converged.push_back(r.state);
      finals.emplace_back(r, screened[i].start);
      if (!have || r.cost < best.cost) {
        best = std::move(r);
        best_start = screened[i].start;
        have = true;
      }
    }
    if (finals.size() > 1) {
      std::stable_sort(finals.begin(), finals.end(),
                       [](const auto& a, const auto& b) { return a.first.cost < b.first.cost; });
      std::vector<const JointProblem::Result*> by_cost;
      for (const auto& f : finals) by_cost.push_back(&f.first);
      const size_t c = cheiralChoice(by_cost);
      if (c > 0) {
        best = finals[c].first;
        best_start = finals[c].second;
      }
    }
  }
  // ml.cheiral_min: the answer must put the clusters' lines in front of the
  // camera; if it does not, the lowest screened end point that does, within
  // ml.cheiral_clusters clusters' share of the lowest screened cost, is
  // refined to convergence and replaces it (MlOptions::cheiral_min).
  std::string cheiral_note;
  if (options.ml.cheiral_min > 0.0) {
    auto marginAt = [&](const Vec3& v) { return std::abs(resolveSign(obs, motion, v, frames).margin); };
    const double answer_margin = marginAt(best.state.v);
    if (answer_margin < options.ml.cheiral_min) {
      std::vector<const End*> by_cost;
      for (const End& e : screened) by_cost.push_back(&e);
      std::stable_sort(by_cost.begin(), by_cost.end(),
                       [](const End* a, const End* b) { return a->result.cost < b->result.cost; });
      const double low = std::max(by_cost.front()->result.cost, 1e-300);
      const double clusters = static_cast<double>(problem.clusters());
      for (const End* e : by_cost) {
        if (clusters * (e->result.cost - low) / low > options.ml.cheiral_clusters) break;
        if (marginAt(e->result.state.v) < options.ml.cheiral_min) continue;
        JointProblem::Result r = problem.refine(e->result.state, iterations, tolerance, 1);
        if (!r.ok) continue;
        const double m = marginAt(r.state.v);
        if (m < options.ml.cheiral_min) continue;
        char text[200];
        std::snprintf(text, sizeof text,
                      "answer in front of the camera: sign margin %.2f against %.2f at the lowest cost "
                      "(%.1f deg away)",
                      m, answer_margin, angleBetweenSignAgnostic(r.state.v, best.state.v) * 180.0 / M_PI);
        cheiral_note = text;
        best = std::move(r);
        best_start = e->start;
        break;
      }
    }
  }
  // ml.rate_offset: where the events ask for an offset of the given rate
  // (rate_offset.hpp), the rest runs with the gyro shifted by it.
  std::optional<MotionModel> shifted_motion;
  std::optional<WindowFrames> shifted_frames;
  std::optional<JointProblem> shifted_problem;
  JointProblem* active = &problem;
  std::string note;
  if (options.ml.rate_offset) {
    const RateOffsetFit fit = searchRateOffset(obs, motion, best.state.v, options, event_seed, problem.lossScale());
    if (fit.accepted) {
      shifted_motion.emplace(motion.withOmegaOffset(fit.delta));
      shifted_frames.emplace(obs, *shifted_motion);
      shifted_problem.emplace(obs, *shifted_motion, *shifted_frames, options.ml.max_events,
                              options.refine.balance_clusters, event_seed, problem.lossScale());
      JointProblem::Result r = shifted_problem->refine(shifted_problem->start(fit.v), iterations, tolerance, 1);
      if (r.ok) {
        best = std::move(r);
        active = &*shifted_problem;
        const Vec3 d = fit.delta * 180.0 / M_PI;
        char text[160];
        std::snprintf(text, sizeof text, "rate offset (%.2f, %.2f, %.2f) deg/s estimated (likelihood ratio %.1f)",
                      d.x(), d.y(), d.z(), fit.likelihood_ratio);
        note = text;
      }
    }
  }
  const MotionModel& used_motion = shifted_motion ? *shifted_motion : motion;
  const WindowFrames& used_frames = shifted_frames ? *shifted_frames : frames;
  if (end && !shifted_motion) *end = MlEnd{best.state.m1, best.state.m3, active->lossScale(), true};
  // The residual reported is the Huber cost's (the starts' competition).
  const double residual_px = std::sqrt(2.0 * best.cost / std::max(1, best.events));
  // A last refinement under a redescending loss, from the winner (the basin
  // is chosen under Huber, whose cost has fewer minima), where the residuals
  // have a heavier tail than Gaussian noise gives: Cauchy's at
  // ml.cauchy_scale robust scales, or with ml.tukey_scale > 0 Tukey's
  // biweight at that many (an event beyond has no pull at all).
  if (options.ml.cauchy_scale > 0.0) {
    const ResidualSpread spread = active->spread(best.state);
    const bool tukey = options.ml.tukey_scale > 0.0;
    const double scale_px = spread.cauchyScale(tukey ? options.ml.tukey_scale : options.ml.cauchy_scale,
                                               options.ml.cauchy_min_tail);
    if (scale_px > 0.0) {
      active->setLoss(tukey ? JointProblem::Loss::Tukey : JointProblem::Loss::Cauchy, scale_px);
      JointProblem::Result r = active->refine(best.state, iterations, tolerance, 1);
      if (r.ok) best = std::move(r);
    }
  }
  SolverResult out;
  out.status = SolveStatus::Ok;
  for (const std::string* part : {&tie_note, &cheiral_note, &note})
    if (!part->empty()) out.message += (out.message.empty() ? "" : "; ") + *part;
  out.v = best.state.v.dot(best_start->v) < 0 ? Vec3(-best.state.v) : best.state.v;  // keep the start's sign
  out.residual_px = residual_px;
  out.iterations = best.iterations;
  out.rows_used = best.events;
  // The winner keeps its start's singular values and sign margin; a start
  // that is no method's estimate has its sign resolved by cheirality.
  if (const SolverResult* from = best_start->from) {
    out.sigma_min = from->sigma_min;
    out.sigma_second = from->sigma_second;
    out.sign_margin = from->sign_margin;
  } else {
    out.sigma_min = linear.sigma_min;
    out.sigma_second = linear.sigma_second;
    if (options.linear.resolve_sign) {
      const SignDecision sd = resolveSign(obs, used_motion, out.v, used_frames);
      out.v *= sd.sign;
      out.sign_margin = sd.margin * sd.sign;
    }
  }
  out.time_us =
      time_us + std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace celc::detail
