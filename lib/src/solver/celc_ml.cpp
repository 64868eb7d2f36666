// celc_ml: the joint refinement of v and the lines from several starts.
#include "celc_ml.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
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

namespace {

/// A start of the joint refinement: a direction and the method whose estimate
/// it is (null: a direction of the profile or the lattice).
struct Start {
  Vec3 v;
  const SolverResult* from;
};

/// A refined start: its end point with its cost, and the start it came from.
struct End {
  JointProblem::Result result;
  const Start* start;
};

/// The refinements' budget: the screen runs start_iterations on every
/// stride-th event, a refinement to convergence `iterations`.
struct Schedule {
  int stride = 1;
  int iterations = 0;
  int start_iterations = 0;
  double tolerance = 0.0;  ///< relative cost decrease that ends a refinement
  /// Whether the screen's costs are partial (fewer events or iterations),
  /// so that its lowest end points are refined again to convergence.
  bool partial() const { return stride > 1 || start_iterations < iterations; }
};

/// The window the cheirality tests read: observations, motion and frames.
struct SignView {
  const WindowObservations& obs;
  const MotionModel& motion;
  const WindowFrames& frames;
  /// |sign margin| of v (sign_test.hpp).
  double margin(const Vec3& v) const { return std::abs(resolveSign(obs, motion, v, frames).margin); }
};

/// An end point's position in a cost order and the note explaining it
/// (empty where the lowest cost stands).
struct Choice {
  size_t index = 0;
  std::string note;
};

/// An end point that replaces the answer and the note that says why.
struct Pick {
  End end;
  std::string note;
};

/// Without a refined start: the linear estimate, npt's where only npt is ok,
/// or the linear stage's status.
SolverResult fallback(const SolverResult& linear, const SolverResult* npt) {
  return linear.ok() || !npt || !npt->ok() ? linear : *npt;
}

/// The methods' estimates as starts: the linear one (an ambiguous nullspace's
/// too: it still points into a valley of the cost), then npt's.
std::vector<Start> methodStarts(const SolverResult& linear, const SolverResult* npt) {
  std::vector<Start> starts;
  if (linear.ok()) starts.push_back({linear.v, &linear});
  else if (linear.degeneracy == Degeneracy::NullspaceNotUnique && linear.v.norm() > 0.5)
    starts.push_back({linear.v, nullptr});
  if (npt && npt->ok()) starts.push_back({npt->v, npt});
  return starts;
}

/// The line profile's minima as starts (none with ml.profile_lattice 0).
/// They need no linear estimate: a window whose linear stage found its
/// nullspace ambiguous (two near-equal singular values) is still answered.
std::vector<Start> profileStarts(const WindowObservations& obs, const MotionModel& motion,
                                 const WindowFrames& frames, const MlOptions& ml, std::uint64_t event_seed) {
  std::vector<Start> starts;
  if (ml.profile_lattice <= 0) return starts;
  const LineProfile profile(obs, motion, frames.clusters(), ml.profile_events, event_seed);
  for (const ScreenMinimum& m :
       screenProfile(profile, ml.profile_lattice, ml.profile_starts, kProfileToleranceDeg, ml.second_start_deg))
    starts.push_back({m.v, nullptr});
  return starts;
}

/// The budget for `starts` starts on a problem of `events` events. With
/// several starts, each is refined on every stride-th event (the basins are
/// coarse; every start sees the same events, so the costs compare) and for
/// ml.start_iterations at most; with one, on every event to convergence.
Schedule scheduleFor(size_t starts, size_t events, const SolverOptions& options) {
  Schedule s;
  s.stride = starts > 1 && options.ml.screen_events > 0 && events > static_cast<size_t>(options.ml.screen_events)
                 ? static_cast<int>((events + options.ml.screen_events - 1) /
                                    static_cast<size_t>(options.ml.screen_events))
                 : 1;
  s.iterations = options.refine.max_iterations;
  s.tolerance = options.refine.function_tolerance;
  s.start_iterations = starts > 1 && options.ml.start_iterations > 0
                           ? std::min(options.ml.start_iterations, s.iterations)
                           : s.iterations;
  return s;
}

/// How far r's cost lies above low_cost, N (C - C_low) / C_low (the tie's units).
double unitsAbove(const JointProblem::Result& r, double low_cost) {
  return r.events * (r.cost - low_cost) / std::max(low_cost, 1e-300);
}

/// The results of `ends` in their order.
std::vector<const JointProblem::Result*> results(const std::vector<End>& ends) {
  std::vector<const JointProblem::Result*> out;
  for (const End& e : ends) out.push_back(&e.result);
  return out;
}

/// `ends` sorted by cost (stable: equal costs keep their order).
void sortByCost(std::vector<End>& ends) {
  std::stable_sort(ends.begin(), ends.end(), [](const End& a, const End& b) { return a.result.cost < b.result.cost; });
}

/// ml.cheiral_tie: among the end points of `by_cost` (ascending cost) tied
/// with the lowest (within `tie` units), the one whose clusters agree best
/// on the cheirality sign; index 0 and no note without a tie or with tie 0.
Choice cheiralChoice(const std::vector<const JointProblem::Result*>& by_cost, const SignView& view, double tie) {
  Choice choice;
  if (!(tie > 0.0) || by_cost.size() < 2) return choice;
  const JointProblem::Result& low = *by_cost.front();
  if (!(unitsAbove(*by_cost[1], low.cost) <= tie)) return choice;  // no tie: no sign test
  const double low_margin = view.margin(low.state.v);
  double best_margin = low_margin;
  for (size_t i = 1; i < by_cost.size(); ++i) {
    if (!(unitsAbove(*by_cost[i], low.cost) <= tie)) break;
    const double margin = view.margin(by_cost[i]->state.v);
    if (margin > best_margin + 1e-9) {
      best_margin = margin;
      choice.index = i;
    }
  }
  if (choice.index > 0) {
    const JointProblem::Result& r = *by_cost[choice.index];
    char text[200];
    std::snprintf(text, sizeof text,
                  "basin chosen by cheirality: sign margin %.2f against %.2f at the lowest cost, %.2f units "
                  "above it (%.1f deg away)",
                  best_margin, low_margin, unitsAbove(r, low.cost),
                  angleBetweenSignAgnostic(r.state.v, low.state.v) * 180.0 / M_PI);
    choice.note = text;
  }
  return choice;
}

/// The screen: every start not within ml.second_start_deg of an earlier end
/// point refined from the fitted lines under the schedule's screen budget,
/// sorted by cost. A start that comes within kMergeDeg of an earlier end
/// point, in v and in every line, would follow its descent and stops there
/// (docs/accuracy.md). With ml.huber_scale, the first end point's residuals
/// set the problem's Huber threshold (ml.huber_scale robust scales, never
/// below refine.huber_px) for every start, the first refined again under it.
std::vector<End> screenStarts(JointProblem& problem, const std::vector<Start>& starts, const Schedule& s,
                              const SolverOptions& options) {
  std::vector<End> screened;
  std::vector<JointProblem::State> ends;
  for (const Start& start : starts) {
    bool seen = false;
    for (const JointProblem::State& e : ends)
      seen = seen || angleBetweenSignAgnostic(start.v, e.v) * 180.0 / M_PI < options.ml.second_start_deg;
    if (seen) continue;
    // Every start begins at the fitted lines (measured: the profile's own
    // lines for its minima did worse at parallax 0.125, RMS 6.2 -> 10.1 deg).
    JointProblem::Result r = problem.refine(problem.start(start.v), s.start_iterations, s.tolerance, s.stride,
                                            ends, kMergeDeg * M_PI / 180.0);
    if (!r.ok || r.merged) continue;
    if (options.ml.huber_scale > 0.0 && ends.empty()) {
      const double scaled = options.ml.huber_scale * problem.robustScale(r.state);
      if (scaled > options.refine.huber_px) {
        problem.setLoss(RobustLoss::huber(scaled));
        JointProblem::Result again = problem.refine(r.state, s.start_iterations, s.tolerance, s.stride);
        if (!again.ok) continue;
        r = std::move(again);
      }
    }
    ends.push_back(r.state);
    screened.push_back({std::move(r), &start});
  }
  sortByCost(screened);
  return screened;
}

/// The finalists' round after a partial screen: the near-tied basins can
/// swap places on convergence, so the ml.finalists lowest screened end
/// points are refined on every event and the lowest converged cost wins
/// (docs/method.md, "celc_ml's finalists"). The first runs to convergence;
/// a later one runs start_iterations and continues only while within the
/// tie of the best (below it, with no tie), and one heading into a basin an
/// earlier finalist ended in stops there. Returns the winner (the screen's
/// lowest when none converged) and the finalists that converged, in order.
std::pair<End, std::vector<End>> convergeFinalists(const JointProblem& problem, const std::vector<End>& screened,
                                                   const Schedule& s, const MlOptions& ml) {
  End best = screened.front();
  std::vector<End> finals;
  std::vector<JointProblem::State> converged;
  bool have = false;
  const double merge_rad = kMergeDeg * M_PI / 180.0;
  const size_t finalists = static_cast<size_t>(std::max(1, ml.finalists));
  for (size_t i = 0; i < screened.size() && i < finalists; ++i) {
    JointProblem::Result r = problem.refine(screened[i].result.state, have ? s.start_iterations : s.iterations,
                                            s.tolerance, 1, converged, merge_rad);
    if (!r.ok || r.merged || (have && unitsAbove(r, best.result.cost) >= ml.cheiral_tie)) continue;
    if (have && r.iterations == s.start_iterations && s.start_iterations < s.iterations) {
      JointProblem::Result rest = problem.refine(r.state, s.iterations, s.tolerance, 1, converged, merge_rad);
      if (!rest.ok || rest.merged) continue;
      rest.iterations += r.iterations;
      r = std::move(rest);
    }
    converged.push_back(r.state);
    finals.push_back({r, screened[i].start});
    if (!have || r.cost < best.result.cost) {
      best = {std::move(r), screened[i].start};
      have = true;
    }
  }
  return {std::move(best), std::move(finals)};
}

/// The finalists' winner and, where several converged, the note of the
/// ml.cheiral_tie choice among them (possibly empty), which replaces the
/// screen's.
struct FinalRound {
  End best;
  std::optional<std::string> tie_note;
};

/// convergeFinalists, then ml.cheiral_tie among the converged finalists.
FinalRound finalRound(const JointProblem& problem, const std::vector<End>& screened, const Schedule& s,
                      const SignView& view, const MlOptions& ml) {
  auto [best, finals] = convergeFinalists(problem, screened, s, ml);
  if (finals.size() < 2) return {std::move(best), std::nullopt};
  sortByCost(finals);
  Choice choice = cheiralChoice(results(finals), view, ml.cheiral_tie);
  if (choice.index > 0) best = finals[choice.index];
  return {std::move(best), std::move(choice.note)};
}

/// ml.cheiral_min: where `answer` does not put the clusters' lines in front
/// of the camera, the lowest screened end point that does, within
/// ml.cheiral_clusters clusters' share of the lowest screened cost, refined
/// to convergence (MlOptions::cheiral_min); nothing otherwise.
std::optional<Pick> inFrontOfCamera(const JointProblem& problem, const std::vector<End>& screened,
                                    const End& answer, const Schedule& s, const SignView& view,
                                    const MlOptions& ml) {
  if (!(ml.cheiral_min > 0.0)) return std::nullopt;
  const double answer_margin = view.margin(answer.result.state.v);
  if (!(answer_margin < ml.cheiral_min)) return std::nullopt;
  std::vector<const End*> by_cost;
  for (const End& e : screened) by_cost.push_back(&e);
  std::stable_sort(by_cost.begin(), by_cost.end(),
                   [](const End* a, const End* b) { return a->result.cost < b->result.cost; });
  const double low = std::max(by_cost.front()->result.cost, 1e-300);
  const double clusters = static_cast<double>(problem.clusters());
  for (const End* e : by_cost) {
    if (clusters * (e->result.cost - low) / low > ml.cheiral_clusters) break;
    if (view.margin(e->result.state.v) < ml.cheiral_min) continue;
    JointProblem::Result r = problem.refine(e->result.state, s.iterations, s.tolerance, 1);
    if (!r.ok) continue;
    const double m = view.margin(r.state.v);
    if (m < ml.cheiral_min) continue;
    char text[200];
    std::snprintf(text, sizeof text,
                  "answer in front of the camera: sign margin %.2f against %.2f at the lowest cost "
                  "(%.1f deg away)",
                  m, answer_margin, angleBetweenSignAgnostic(r.state.v, answer.result.state.v) * 180.0 / M_PI);
    return Pick{{std::move(r), e->start}, text};
  }
  return std::nullopt;
}

/// The window with the gyro shifted by an estimated rate offset: the fit,
/// the shifted motion, its frames and its joint problem (each refers to the
/// ones before: the object stays where it was built).
struct ShiftedWindow {
  ShiftedWindow(const WindowObservations& obs, const MotionModel& base, const RateOffsetFit& rate_fit,
                const SolverOptions& options, std::uint64_t event_seed, double loss_scale)
      : fit(rate_fit),
        motion(base.withOmegaOffset(rate_fit.delta)),
        frames(obs, motion),
        problem(obs, motion, frames, options.ml.max_events, options.refine.balance_clusters, event_seed,
                loss_scale) {}
  RateOffsetFit fit;
  MotionModel motion;
  WindowFrames frames;
  JointProblem problem;
};

/// ml.rate_offset: the shifted window where the events ask for an offset of
/// the given rate (rate_offset.hpp), searched from v under the problem's
/// loss scale; null otherwise.
std::unique_ptr<ShiftedWindow> rateShift(const WindowObservations& obs, const MotionModel& motion, const Vec3& v,
                                         const SolverOptions& options, std::uint64_t event_seed,
                                         double loss_scale) {
  if (!options.ml.rate_offset) return nullptr;
  const RateOffsetFit fit = searchRateOffset(obs, motion, v, options, event_seed, loss_scale);
  if (!fit.accepted) return nullptr;
  return std::make_unique<ShiftedWindow>(obs, motion, fit, options, event_seed, loss_scale);
}

/// The note for an accepted rate offset.
std::string rateOffsetNote(const RateOffsetFit& fit) {
  const Vec3 d = fit.delta * 180.0 / M_PI;
  char text[160];
  std::snprintf(text, sizeof text, "rate offset (%.2f, %.2f, %.2f) deg/s estimated (likelihood ratio %.1f)",
                d.x(), d.y(), d.z(), fit.likelihood_ratio);
  return text;
}

/// A last refinement of `best` under a redescending loss (the basin is
/// chosen under Huber, whose cost has fewer minima), where the residuals
/// have a heavier tail than Gaussian noise gives: Cauchy's at
/// ml.cauchy_scale robust scales, or with ml.tukey_scale > 0 Tukey's
/// biweight at that many (an event beyond has no pull at all). Sets the
/// problem's loss when it runs; returns `best` where it does not or fails.
JointProblem::Result redescend(JointProblem& problem, JointProblem::Result best, const Schedule& s,
                               const MlOptions& ml) {
  if (!(ml.cauchy_scale > 0.0)) return best;
  const ResidualSpread spread = problem.spread(best.state);
  const RobustLoss loss = redescendingLoss(ml.cauchy_scale, ml.tukey_scale,
                                           [&](double k) { return spread.cauchyScale(k, ml.cauchy_min_tail); });
  if (loss.type == RobustLoss::Type::None) return best;
  problem.setLoss(loss);
  JointProblem::Result r = problem.refine(best.state, s.iterations, s.tolerance, 1);
  return r.ok ? r : best;
}

/// ml.cluster_test: the cluster whose events disagree most with the others'
/// at `best` (JointProblem::clusterAgreement, above ml.cluster_test) left out
/// of `problem` and v refined again under the problem's loss, one cluster at
/// a time until none disagrees, at most a tenth of the clusters (at least
/// one). A step whose answer puts the lines less in front of the camera than
/// ml.cheiral_min (or than before, where that was below it) is not taken, and
/// the test stops there. Returns the clusters left out (observation indices).
std::vector<int> leaveOutDisagreeing(JointProblem& problem, JointProblem::Result& best, const Schedule& s,
                                     const SignView& view, const MlOptions& ml) {
  std::vector<int> left;
  if (!(ml.cluster_test > 0.0)) return left;
  const size_t most = std::max<size_t>(1, problem.clusters() / 10);
  double margin = view.margin(best.state.v);
  while (left.size() < most) {
    const std::vector<double> T = problem.clusterAgreement(best.state, problem.robustScale(best.state));
    size_t worst = T.size();
    for (size_t c = 0; c < T.size(); ++c)
      if (T[c] > ml.cluster_test && (worst == T.size() || T[c] > T[worst])) worst = c;
    if (worst == T.size()) break;
    problem.leaveOut({worst});
    JointProblem::Result r = problem.refine(best.state, s.iterations, s.tolerance, 1);
    const double m = r.ok ? view.margin(r.state.v) : 0.0;
    if (!r.ok || m < std::min(margin, ml.cheiral_min)) {
      problem.takeBack(worst);
      break;
    }
    best = std::move(r);
    margin = m;
    left.push_back(problem.observationIndex()[worst]);
  }
  return left;
}

/// A method's sign says nothing of an answer 60 deg or more from its
/// estimate. Applied with ml.cluster_test on, whose leaving out and the
/// redraws that follow carry answers far from their starts; with the
/// defaults it would move one held-out window in 136 (docs/decisions.md).
constexpr double kStartSignMinCos = 0.5;

/// The solver's result from the winning end point: v with its start's sign;
/// the start's singular values and sign margin, or for a start that is no
/// method's estimate the linear stage's singular values; the sign by
/// cheirality in `used` (with linear.resolve_sign) where the start is no
/// method's estimate or, with ml.cluster_test, lies 60 deg or more from v;
/// the non-empty notes joined by "; ".
SolverResult answer(const End& best, double residual_px, const SolverResult& linear,
                    const std::vector<std::string>& notes, const SignView& used, const SolverOptions& options) {
  SolverResult out;
  out.status = SolveStatus::Ok;
  for (const std::string& part : notes)
    if (!part.empty()) out.message += (out.message.empty() ? "" : "; ") + part;
  const JointProblem::State& state = best.result.state;
  out.v = state.v.dot(best.start->v) < 0 ? Vec3(-state.v) : state.v;
  out.residual_px = residual_px;
  out.iterations = best.result.iterations;
  out.rows_used = best.result.events;
  const SolverResult* from = best.start->from;
  out.sigma_min = from ? from->sigma_min : linear.sigma_min;
  out.sigma_second = from ? from->sigma_second : linear.sigma_second;
  const bool far_from_start = options.ml.cluster_test > 0.0 && std::abs(state.v.dot(best.start->v)) < kStartSignMinCos;
  if (from && !far_from_start) {
    out.sign_margin = from->sign_margin;
  } else if (options.linear.resolve_sign) {
    const SignDecision sd = resolveSign(used.obs, used.motion, out.v, used.frames);
    out.v *= sd.sign;
    out.sign_margin = sd.margin * sd.sign;
  }
  return out;
}

}  // namespace

SolverResult solveCelcMl(const WindowObservations& obs, const MotionModel& motion,
                         const SolverResult& linear, const SolverResult* npt,
                         const SolverOptions& options, const WindowFrames& frames,
                         std::uint64_t event_seed, MlEnd* end) {
  if (end) *end = MlEnd{};
  // The joint problem has several minima (docs/accuracy.md): every start is refined.
  std::vector<Start> starts = methodStarts(linear, npt);
  const auto t0 = std::chrono::steady_clock::now();
  for (const Start& s : profileStarts(obs, motion, frames, options.ml, event_seed)) starts.push_back(s);
  if (starts.empty()) return linear;  // no start at all: the linear stage's status
  for (const Vec3& d : hemisphereDirections(options.ml.grid_starts)) starts.push_back({d, nullptr});
  const double time_us = linear.time_us + (npt ? npt->time_us : 0.0);
  JointProblem problem(obs, motion, frames, options.ml.max_events, options.refine.balance_clusters,
                       event_seed, options.refine.huber_px);
  if (problem.events() < 3) return fallback(linear, npt);
  const Schedule schedule = scheduleFor(starts.size(), problem.events(), options);
  std::vector<End> screened = screenStarts(problem, starts, schedule, options);
  if (screened.empty()) return fallback(linear, npt);

  // The answer: the lowest cost, or among costs tied with it the best sign margin.
  const SignView view{obs, motion, frames};
  Choice screen_tie = cheiralChoice(results(screened), view, options.ml.cheiral_tie);
  const auto chosen = screened.begin() + static_cast<std::ptrdiff_t>(screen_tie.index);
  std::rotate(screened.begin(), chosen, chosen + 1);
  End best = screened.front();
  std::string tie_note = std::move(screen_tie.note);
  if (schedule.partial()) {
    FinalRound round = finalRound(problem, screened, schedule, view, options.ml);
    best = std::move(round.best);
    if (round.tie_note) tie_note = std::move(*round.tie_note);
  }
  std::string cheiral_note;
  if (std::optional<Pick> front = inFrontOfCamera(problem, screened, best, schedule, view, options.ml)) {
    best = std::move(front->end);
    cheiral_note = std::move(front->note);
  }

  // ml.rate_offset: the rest runs with the gyro shifted where the events ask for it.
  const std::unique_ptr<ShiftedWindow> shift =
      rateShift(obs, motion, best.result.state.v, options, event_seed, problem.loss().scale);
  JointProblem* active = &problem;
  std::string rate_note;
  if (shift) {
    JointProblem::Result r =
        shift->problem.refine(shift->problem.start(shift->fit.v), schedule.iterations, schedule.tolerance, 1);
    if (r.ok) {
      best.result = std::move(r);
      active = &shift->problem;
      rate_note = rateOffsetNote(shift->fit);
    }
  }
  if (end && !shift) *end = MlEnd{best.result.state.m1, best.result.state.m3, active->loss().scale, true};
  // The residual reported is the Huber cost's (the starts' competition).
  const double residual_px = std::sqrt(2.0 * best.result.cost / std::max(1, best.result.events));
  best.result = redescend(*active, std::move(best.result), schedule, options.ml);
  const SignView used = shift ? SignView{obs, shift->motion, shift->frames} : view;
  std::string test_note;
  if (const std::vector<int> left = leaveOutDisagreeing(*active, best.result, schedule, used, options.ml);
      !left.empty())
    test_note = std::to_string(left.size()) + " clusters left out by the agreement test";
  SolverResult out = answer(best, residual_px, linear, {tie_note, cheiral_note, rate_note, test_note}, used, options);
  out.time_us =
      time_us + std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace celc::detail
