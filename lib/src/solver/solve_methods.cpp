// The method dispatcher: the window checks once, the clusters' frames once,
// then every requested method (celc computed once for the methods it starts).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ce3lc.hpp"
#include "celc/core/parallel.hpp"
#include "celc/solver/direction_information.hpp"
#include "celc/solver/error_budget.hpp"
#include "celc/solver/npt.hpp"
#include "celc/solver/solver.hpp"
#include "celc_acc.hpp"
#include "celc_linear.hpp"
#include "celc_ml.hpp"
#include "constraint_rows.hpp"
#include "linear_method.hpp"
#include "refine.hpp"
#include "sign_test.hpp"
#include "stopwatch.hpp"
#include "window_checks.hpp"

namespace celc {

namespace {

/// Seeds the witness subset of UncertaintyOptions::witness_rows apart from the estimate's.
constexpr std::uint64_t kWitnessSeed = 0x9e3779b97f4a7c15ULL;

/// sigma_i at least the largest angle to a disagreeing witness
/// (UncertaintyOptions::agreement). `witnesses` holds estimates with their
/// sigma parts, `counts` whether each may raise r; `self` is r's own witness
/// index or -1. The test compares the
/// Fisher parts alone: the budget's errors move every estimate alike.
void raiseToDisagreement(SolverResult& r, int self, const std::vector<SolverResult>& witnesses,
                         const std::vector<bool>& counts) {
  const double sigma = r.sigma_deg;
  double raised = sigma;
  for (size_t j = 0; j < witnesses.size(); ++j) {
    if (static_cast<int>(j) == self || !counts[j]) continue;
    const double angle_deg = angleBetweenSignAgnostic(r.v, witnesses[j].v) * 180.0 / M_PI;
    if (angle_deg > 2.0 * std::hypot(r.sigma_fisher_deg, witnesses[j].sigma_fisher_deg))
      raised = std::max(raised, angle_deg);
  }
  if (raised > sigma) {
    r.sigma_deg = raised;
    r.sigma_rule = "disagreement";
  }
}

/// LinearOptions::answer_when_observable: a linear method's ambiguous
/// nullspace becomes an answer when the events' bound at its direction (unit
/// method scale) is within max_nullspace_sigma_deg; its sign is then resolved.
/// Returns the std the rows imply [deg], the floor of the answer's sigma_deg,
/// or 0 when `r` is left as it was.
double answerIfObservable(const WindowObservations& obs, const MotionModel& motion, const LinearOptions& opt,
                          const DirectionTerms& bound_terms, const detail::WindowFrames& frames, SolverResult& r) {
  if (r.degeneracy != Degeneracy::NullspaceNotUnique || !r.v.allFinite() || !(r.v.norm() > 0.5)) return 0.0;
  const auto t0 = detail::Clock::now();
  const double bound_deg = bound_terms.sigmaDeg(r.v, 1.0);
  if (!(bound_deg <= opt.max_nullspace_sigma_deg)) {
    r.time_us += detail::microsecondsSince(t0);
    return 0.0;
  }
  const double rows_deg = detail::impliedNullspaceSigmaDeg(r.sigma_min, r.sigma_second, r.rows_used);
  if (opt.resolve_sign) {
    const SignDecision s = detail::resolveSign(obs, motion, r.v, frames);
    r.v *= s.sign;
    r.sign_margin = s.margin * s.sign;
  }
  r.time_us += detail::microsecondsSince(t0);
  r.status = SolveStatus::Ok;
  r.degeneracy = Degeneracy::None;
  r.message = "ambiguous nullspace (the rows imply a direction std of " + std::to_string(rows_deg) +
              " deg) answered: the events' bound there is " + std::to_string(bound_deg) + " deg";
  return std::isfinite(rows_deg) ? rows_deg : 180.0;
}

/// sigma_deg of an estimate whose clusters' cheirality votes disagree
/// (UncertaintyOptions::cheiral_min) at least this [deg]: the RMS angle of a random
/// direction to a fixed one, sign-agnostic, sqrt(pi - 2) rad.
constexpr double kRandomDirectionRmsDeg = 61.2;

/// Seeds celc_opt's further starts (RefineOptions::starts): subset k's seed is
/// the window's row seed XOR k times this.
constexpr std::uint64_t kRestartSeed = 0xd1b54a32d192ed03ULL;
/// celc_opt's further starts this close to one already refined are skipped [deg].
constexpr double kSameStartDeg = 1.0;

/// Whether celc_opt can start from a linear result: an answer, or an
/// ambiguous nullspace (two near-equal singular values), which still points
/// into the cost's valley.
bool celcOptCanStart(const SolverResult& init) {
  const bool ambiguous = init.degeneracy == Degeneracy::NullspaceNotUnique && init.v.norm() > 0.5;
  return init.ok() || ambiguous;
}

/// celc_opt from one linear result: the Ceres refinement on the fixed lines;
/// from an ambiguous nullspace the sign is resolved at the end point. Its
/// time is the refinement's alone.
SolverResult refineCelcOpt(const WindowObservations& obs, const MotionModel& motion, const SolverResult& init,
                           const SolverOptions& options, const detail::WindowFrames& frames,
                           std::uint64_t event_seed) {
  SolverResult r = detail::refineVelocity(obs, motion, init.v, false, options.refine, frames,
                                          options.refine.max_events, event_seed);
  r.sigma_min = init.sigma_min;
  r.sigma_second = init.sigma_second;
  r.sign_margin = init.sign_margin;
  if (!init.ok() && r.ok() && options.linear.resolve_sign) {
    const auto t0 = detail::Clock::now();
    const SignDecision s = detail::resolveSign(obs, motion, r.v, frames);
    r.v *= s.sign;
    r.sign_margin = s.margin * s.sign;
    r.time_us += detail::microsecondsSince(t0);
  }
  return r;
}

/// celc_opt: refined from celc's estimate `init` and, with
/// RefineOptions::starts > 1, from celc on further row subsets. Several
/// distinct starts are screened (Huber refinement on screen_events events of
/// the same seeded subset, costs compared there); the lowest end point is
/// refined as one start is. Its time includes every linear stage it used.
SolverResult solveCelcOpt(const WindowObservations& obs, const MotionModel& motion, const SolverResult& init,
                          const SolverOptions& options, const detail::WindowFrames& frames,
                          const SampleSeeds& seeds) {
  const RefineOptions& ro = options.refine;
  std::vector<SolverResult> starts{init};
  double time_us = init.time_us;
  // Where every event is a row, every subset is the same: no further start.
  size_t events = 0;
  for (const ClusterObservation& c : obs.clusters) events += c.size();
  const bool subsets_differ = options.linear.max_rows > 0 && events > static_cast<size_t>(options.linear.max_rows);
  for (int k = 1; subsets_differ && k < ro.starts; ++k) {
    const SolverResult alt = detail::solveCelcLinear(obs, motion, options.linear, frames, false,
                                                     seeds.linear_rows ^ (kRestartSeed * static_cast<std::uint64_t>(k)));
    time_us += alt.time_us;
    const bool seen = std::any_of(starts.begin(), starts.end(), [&](const SolverResult& s) {
      return angleBetweenSignAgnostic(s.v, alt.v) * 180.0 / M_PI < kSameStartDeg;
    });
    if (celcOptCanStart(alt) && !seen) starts.push_back(alt);
  }
  SolverResult start = init;
  if (starts.size() > 1) {
    RefineOptions screen = ro;
    screen.cauchy_scale = 0.0;  // Huber only
    const int screen_events = ro.screen_events > 0 ? ro.screen_events : ro.max_events;
    double best_cost = INFINITY;
    for (const SolverResult& s : starts) {
      const SolverResult r =
          detail::refineVelocity(obs, motion, s.v, false, screen, frames, screen_events, seeds.refine_events);
      time_us += r.time_us;
      if (r.ok() && r.residual_px < best_cost) {
        best_cost = r.residual_px;
        start = s;
        start.v = r.v;  // the screen keeps the start's sign
      }
    }
  }
  SolverResult r = refineCelcOpt(obs, motion, start, options, frames, seeds.refine_events);
  r.time_us += time_us;
  return r;
}


}  // namespace

/// The shared estimates as computed (SharedSolves).
struct SharedSolves::Store {
  std::optional<SolverResult> linear, npt, ml;
  detail::MlEnd ml_end;
};

SharedSolves::SharedSolves() : store_(std::make_unique<Store>()) {}
SharedSolves::~SharedSolves() = default;
SharedSolves::SharedSolves(SharedSolves&&) noexcept = default;
SharedSolves& SharedSolves::operator=(SharedSolves&&) noexcept = default;

namespace {

/// The estimates several methods share, each computed on first use and kept
/// in a SharedSolves store: celc's linear estimate, npt's (its sign resolved
/// by cheirality with linear.resolve_sign) and celc_ml's with its end
/// point's lines (celc_acc's start). Refers to its inputs, which outlive it.
class SharedEstimates {
 public:
  SharedEstimates(const WindowObservations& obs, const MotionModel& motion, const SolverOptions& options,
                  const detail::WindowFrames& frames, const SampleSeeds& seeds, SharedSolves::Store& store)
      : obs_(obs), motion_(motion), options_(options), frames_(frames), seeds_(seeds), linear_(store.linear),
        npt_(store.npt), ml_(store.ml), ml_end_(store.ml_end) {}

  /// celc's linear estimate on the rows seeded by seeds.linear_rows.
  const SolverResult& linear() {
    if (!linear_)
      linear_ = detail::solveCelcLinear(obs_, motion_, options_.linear, frames_, false, seeds_.linear_rows);
    return *linear_;
  }
  /// The linear estimate where a method asked for it; null otherwise.
  const SolverResult* linearIfSolved() const { return linear_ ? &*linear_ : nullptr; }

  /// npt's estimate, its sign resolved (and timed) with linear.resolve_sign.
  const SolverResult& npt() {
    if (npt_) return *npt_;
    SolverResult r = solveNpt(obs_, motion_, options_.npt);
    if (r.ok() && options_.linear.resolve_sign) {
      const auto t0 = detail::Clock::now();
      const SignDecision s = detail::resolveSign(obs_, motion_, r.v, frames_);
      r.v *= s.sign;
      r.sign_margin = s.margin * s.sign;
      r.time_us += detail::microsecondsSince(t0);
    }
    npt_ = std::move(r);
    return *npt_;
  }

  /// celc_ml's estimate from the linear one and, where its model holds, npt's.
  const SolverResult& ml() {
    if (ml_) return *ml_;
    const bool npt_start = detail::nptStartApplies(obs_, motion_, options_.ml);
    const SolverResult& from_linear = linear();
    const SolverResult* from_npt = npt_start ? &npt() : nullptr;
    ml_ = detail::solveCelcMl(obs_, motion_, from_linear, from_npt, options_, frames_, seeds_.refine_events,
                              &ml_end_);
    return *ml_;
  }
  /// celc_ml's end point's lines (ml() computed first).
  const detail::MlEnd& mlEnd() {
    ml();
    return ml_end_;
  }

 private:
  const WindowObservations& obs_;
  const MotionModel& motion_;
  const SolverOptions& options_;
  const detail::WindowFrames& frames_;
  const SampleSeeds& seeds_;
  std::optional<SolverResult>& linear_;
  std::optional<SolverResult>& npt_;
  std::optional<SolverResult>& ml_;
  detail::MlEnd& ml_end_;
};

/// Solves the shared estimates that solveMethod reads for `methods` (keep
/// the two in step), so that the methods then only read them and can run
/// side by side. npt's is left to npt itself where celc_ml did not need it
/// and npt is asked once.
void solveSharedFirst(const std::vector<Method>& methods, SharedEstimates& shared) {
  const auto count = [&](Method m) { return std::count(methods.begin(), methods.end(), m); };
  if (count(Method::Celc) + count(Method::CelcOpt) + count(Method::CelcAcc) > 0) shared.linear();
  if (count(Method::CelcMl) + count(Method::CelcAcc) > 0) shared.ml();
  if (count(Method::Npt) > 1) shared.npt();
}

/// Method m's result on the window, the shared estimates taken from `shared`
/// (solveSharedFirst solves them first).
SolverResult solveMethod(Method m, SharedEstimates& shared, const WindowObservations& obs,
                         const MotionModel& motion, const SolverOptions& options,
                         const detail::WindowFrames& frames, const SampleSeeds& seeds) {
  switch (m) {
    case Method::Celc: return shared.linear();
    case Method::Ce3lc: return detail::solveCe3lc(obs, motion, options.linear, frames, false);
    case Method::Npt: return shared.npt();
    case Method::CelcAcc: {
      const SolverResult& ml = shared.ml();
      return detail::solveCelcAcc(obs, motion, shared.linear(), ml, shared.mlEnd(), options, frames,
                                  seeds.linear_rows, seeds.refine_events);
    }
    case Method::CelcMl: return shared.ml();
    case Method::CelcOpt: {
      const SolverResult& init = shared.linear();
      return celcOptCanStart(init) ? solveCelcOpt(obs, motion, init, options, frames, seeds) : init;
    }
  }
  return SolverResult{};
}

/// The window's uncertainty model: the events' terms of the bound and the
/// model-error budget, each formed on first use for every direction asked
/// about. Refers to its inputs, which outlive it.
class UncertaintyModel {
 public:
  UncertaintyModel(const WindowObservations& obs, const MotionModel& motion, const UncertaintyOptions& u)
      : obs_(obs), motion_(motion), u_(u) {}

  /// The events' terms of the bound (u.max_events events).
  const DirectionTerms& terms() {
    if (!terms_) terms_.emplace(obs_, motion_, u_.max_events);
    return *terms_;
  }
  /// The budget's sigma [deg] at v: 0 with no source, NaN where it fails.
  /// Methods that answer the very same v (celc_acc keeping celc_ml's
  /// constant velocity) share one evaluation.
  double budgetDeg(const Vec3& v) {
    if (!budget_) budget_.emplace(obs_, motion_, u_);
    if (budget_->sources() == 0) return 0.0;
    for (const auto& [asked, deg] : budget_at_)
      if (asked == v) return deg;
    const double deg = budget_->sigmaDeg(terms(), v);
    budget_at_.emplace_back(v, deg);
    return deg;
  }
  /// Sets r's Fisher sigma (times `scale`), its budget and sigma_deg, the two
  /// in quadrature (infinite where the budget fails).
  void setSigma(SolverResult& r, double scale) {
    r.sigma_fisher_deg = terms().sigmaDeg(r.v, scale);
    r.sigma_budget_deg = budgetDeg(r.v);
    r.sigma_deg = std::isnan(r.sigma_budget_deg) ? INFINITY : std::hypot(r.sigma_fisher_deg, r.sigma_budget_deg);
  }

 private:
  const WindowObservations& obs_;
  const MotionModel& motion_;
  const UncertaintyOptions& u_;
  std::optional<DirectionTerms> terms_;
  std::optional<ErrorBudget> budget_;
  std::vector<std::pair<Vec3, double>> budget_at_;  ///< directions asked about and their budget [deg]
};

/// The linear methods' ambiguous verdicts checked against the events' bound
/// (answerIfObservable, applied to `out`): per result, the floor of its
/// sigma_deg [deg], 0 where none.
std::vector<double> answerObservable(std::vector<SolverResult>& out, const std::vector<Method>& methods,
                                     const WindowObservations& obs, const MotionModel& motion,
                                     const LinearOptions& linear, UncertaintyModel& model,
                                     const detail::WindowFrames& frames) {
  std::vector<double> floor_deg(out.size(), 0.0);
  for (size_t i = 0; i < out.size(); ++i)
    if (linear.answer_when_observable && (methods[i] == Method::Celc || methods[i] == Method::Ce3lc) &&
        out[i].degeneracy == Degeneracy::NullspaceNotUnique)
      floor_deg[i] = answerIfObservable(obs, motion, linear, model.terms(), frames, out[i]);
  return floor_deg;
}

/// Per result: whether it is an answer of the celc family (celc_acc's too:
/// an acceleration bends the camera's path by a fraction of what v moves
/// it) that puts the clusters' lines behind the camera (sign margin below
/// u.cheiral_min, with u.enabled).
std::vector<bool> behindCamera(const std::vector<SolverResult>& out, const std::vector<Method>& methods,
                               const WindowObservations& obs, const MotionModel& motion,
                               const UncertaintyOptions& u, const detail::WindowFrames& frames) {
  std::vector<bool> behind(out.size(), false);
  if (!(u.enabled && u.cheiral_min > 0.0)) return behind;
  for (size_t i = 0; i < out.size(); ++i) {
    const bool celc_family = methods[i] == Method::Celc || methods[i] == Method::CelcOpt ||
                             methods[i] == Method::CelcMl || methods[i] == Method::CelcAcc;
    behind[i] = celc_family && out[i].ok() &&
                std::abs(detail::resolveSign(obs, motion, out[i].v, frames).margin) < u.cheiral_min;
  }
  return behind;
}

/// The uncertainty scale of method m's estimates (UncertaintyOptions).
double sigmaScale(Method m, const UncertaintyOptions& u) {
  switch (m) {
    case Method::Celc: return u.scale_celc;
    case Method::CelcOpt: return u.scale_celc_opt;
    case Method::CelcMl: return u.scale_celc_ml;
    case Method::Ce3lc: return u.scale_ce3lc;
    case Method::Npt: return u.scale_npt;
    case Method::CelcAcc: return u.scale_celc_ml;
  }
  return 1.0;
}

/// What every method shares (the window's parallax and lines), and each
/// estimate's sigma_deg at its own direction, at least its floor_deg (NaN
/// where it is no answer or u is off). celc_acc's accelerating answer keeps
/// its own spread (celc_acc.hpp: the bound assumes a constant v), in
/// quadrature with the model-error budget at its direction: the gyro's and
/// the calibration's errors move an accelerating answer as they move a
/// constant velocity's (the budget is that shift).
void setUncertainties(std::vector<SolverResult>& out, const std::vector<Method>& methods,
                      const SolverResult& window, const std::vector<double>& floor_deg, UncertaintyModel& model,
                      const UncertaintyOptions& u) {
  for (size_t i = 0; i < out.size(); ++i) {
    SolverResult& r = out[i];
    r.parallax = window.parallax;
    r.n_lines = window.n_lines;
    if (methods[i] == Method::CelcAcc && r.acceleration_seen) {
      if (!r.ok() || !u.enabled) {
        r.sigma_deg = NAN;
        continue;
      }
      r.sigma_budget_deg = model.budgetDeg(r.v);
      r.sigma_deg = std::isnan(r.sigma_budget_deg) ? INFINITY : std::hypot(r.sigma_deg, r.sigma_budget_deg);
      continue;
    }
    r.sigma_deg = NAN;
    if (!r.ok() || !u.enabled) continue;
    model.setSigma(r, sigmaScale(methods[i], u));
    if (floor_deg[i] > r.sigma_deg) {
      r.sigma_deg = floor_deg[i];
      r.sigma_rule = "ambiguous_nullspace";
    }
    if (r.sigma_floor_deg > r.sigma_deg) {
      r.sigma_deg = r.sigma_floor_deg;
      r.sigma_rule = "accelerometer_refused";
    }
  }
}

/// The estimates the agreement test holds each answer to, with their Fisher
/// sigma; `linear[j]` says whether witness j is a linear estimate, and
/// `of[i]` is result i's own witness index or -1.
struct Witnesses {
  std::vector<SolverResult> estimates;
  std::vector<bool> linear;
  std::vector<int> of;
};

/// Adds the linear estimate r as a witness, with its sigma (times `scale`),
/// where that sigma is finite.
void addLinearWitness(Witnesses& w, SolverResult r, UncertaintyModel& model, double scale) {
  model.setSigma(r, scale);
  if (!std::isfinite(r.sigma_deg)) return;
  w.estimates.push_back(std::move(r));
  w.linear.push_back(true);
}

/// The witnesses: the ok estimates of the celc family with a finite sigma;
/// the linear celc estimate where celc itself was not asked for but solved
/// (`solved_linear`); and with u.witness_rows the linear estimate again on
/// another random subset of rows (a seed apart from the estimate's own),
/// its sampling spread.
Witnesses collectWitnesses(const std::vector<SolverResult>& out, const std::vector<Method>& methods,
                           const SolverResult* solved_linear, UncertaintyModel& model,
                           const WindowObservations& obs, const MotionModel& motion, const SolverOptions& options,
                           const detail::WindowFrames& frames, const SampleSeeds& seeds) {
  const UncertaintyOptions& u = options.uncertainty;
  Witnesses w;
  w.of.assign(out.size(), -1);
  bool celc_asked = false;
  for (size_t i = 0; i < out.size(); ++i) {
    const Method m = methods[i];
    celc_asked = celc_asked || m == Method::Celc;
    if ((m != Method::Celc && m != Method::CelcOpt && m != Method::CelcMl) || !out[i].ok() ||
        !std::isfinite(out[i].sigma_deg))
      continue;
    w.of[i] = static_cast<int>(w.estimates.size());
    w.estimates.push_back(out[i]);
    w.linear.push_back(m == Method::Celc);
  }
  // A linear witness raises the refined methods' sigma only with
  // u.linear_witness_refined: where no other method is asked, it would
  // raise none, and its sigma (a bound and a budget) is not formed.
  bool linear_counts = u.linear_witness_refined;
  for (Method m : methods)
    linear_counts = linear_counts || (m != Method::CelcOpt && m != Method::CelcMl && m != Method::CelcAcc);
  if (!linear_counts) return w;
  if (!celc_asked && solved_linear && solved_linear->ok()) addLinearWitness(w, *solved_linear, model, u.scale_celc);
  if (u.witness_rows > 0 && solved_linear) {
    LinearOptions subset = options.linear;
    subset.max_rows = u.witness_rows;
    SolverResult r = detail::solveCelcLinear(obs, motion, subset, frames, false, seeds.linear_rows ^ kWitnessSeed);
    if (r.ok()) addLinearWitness(w, std::move(r), model, u.scale_celc);
  }
  return w;
}

/// raiseToDisagreement for every ok answer with a finite sigma against the
/// witnesses; the refined methods' against the linear witnesses only with
/// u.linear_witness_refined. The witnesses assume a constant velocity:
/// celc_acc's accelerating answer is not held to them.
void raiseByWitnesses(std::vector<SolverResult>& out, const std::vector<Method>& methods, const Witnesses& w,
                      const UncertaintyOptions& u) {
  for (size_t i = 0; i < out.size(); ++i) {
    if (!out[i].ok() || !std::isfinite(out[i].sigma_deg)) continue;
    if (methods[i] == Method::CelcAcc && out[i].acceleration_seen) continue;
    const bool refined =
        methods[i] == Method::CelcOpt || methods[i] == Method::CelcMl || methods[i] == Method::CelcAcc;
    std::vector<bool> counts(w.estimates.size(), true);
    if (refined && !u.linear_witness_refined)
      for (size_t j = 0; j < w.estimates.size(); ++j) counts[j] = !w.linear[j];
    raiseToDisagreement(out[i], w.of[i], w.estimates, counts);
  }
}

/// The answers behind the camera get sigma_deg at least
/// kRandomDirectionRmsDeg: applied last, so that they still witness with
/// their Fisher sigma.
void floorBehindCamera(std::vector<SolverResult>& out, const std::vector<bool>& behind) {
  for (size_t i = 0; i < out.size(); ++i)
    if (behind[i] && out[i].sigma_deg < kRandomDirectionRmsDeg) {
      out[i].sigma_deg = kRandomDirectionRmsDeg;
      out[i].sigma_rule = "behind_camera";
    }
}

}  // namespace

std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options, const SampleSeeds& seeds) {
  SharedSolves shared;
  return solveMethods(obs, motion, methods, options, seeds, shared);
}

std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods, const SolverOptions& options,
                                       const SampleSeeds& seeds, SharedSolves& solves, int threads) {
  // Window-level checks once; a degenerate window is degenerate for every method.
  const SolverResult window = detail::checkWindow(obs, motion, options.linear, options.check_parallax);
  if (!window.ok()) return std::vector<SolverResult>(methods.size(), window);
  const detail::WindowFrames frames(obs, motion);
  SharedEstimates shared(obs, motion, options, frames, seeds, solves.store());
  solveSharedFirst(methods, shared);
  std::vector<SolverResult> out(methods.size());
  parallelFor(methods.size(), threads,
              [&](std::size_t i) { out[i] = solveMethod(methods[i], shared, obs, motion, options, frames, seeds); });

  const UncertaintyOptions& u = options.uncertainty;
  UncertaintyModel model(obs, motion, u);
  const std::vector<double> floor_deg = answerObservable(out, methods, obs, motion, options.linear, model, frames);
  const std::vector<bool> behind = behindCamera(out, methods, obs, motion, u, frames);
  setUncertainties(out, methods, window, floor_deg, model, u);
  if (u.enabled && u.agreement) {
    const Witnesses w =
        collectWitnesses(out, methods, shared.linearIfSolved(), model, obs, motion, options, frames, seeds);
    raiseByWitnesses(out, methods, w, u);
  }
  floorBehindCamera(out, behind);
  return out;
}

std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options) {
  return solveMethods(obs, motion, methods, options,
                      SampleSeeds{options.linear.seed, options.refine.seed});
}

}  // namespace celc
