// The method dispatcher: the window checks once, the clusters' frames once,
// then every requested method (celc computed once for the methods it starts).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ce3lc.hpp"
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

std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options, const SampleSeeds& seeds) {
  std::vector<SolverResult> out;
  // Window-level checks once; a degenerate window is degenerate for every method.
  const SolverResult window = detail::checkWindow(obs, motion, options.linear, options.check_parallax);
  if (!window.ok()) return std::vector<SolverResult>(methods.size(), window);
  const detail::WindowFrames frames(obs, motion);
  SolverResult linear;
  bool have_linear = false;
  auto getLinear = [&]() -> const SolverResult& {
    if (!have_linear) {
      linear = detail::solveCelcLinear(obs, motion, options.linear, frames, false, seeds.linear_rows);
      have_linear = true;
    }
    return linear;
  };
  SolverResult npt;
  bool have_npt = false;
  auto getNpt = [&]() -> const SolverResult& {
    if (!have_npt) {
      npt = solveNpt(obs, motion, options.npt);
      if (npt.ok() && options.linear.resolve_sign) {
        const auto t0 = detail::Clock::now();
        const SignDecision s = detail::resolveSign(obs, motion, npt.v, frames);
        npt.v *= s.sign;
        npt.sign_margin = s.margin * s.sign;
        npt.time_us += detail::microsecondsSince(t0);
      }
      have_npt = true;
    }
    return npt;
  };
  SolverResult ml;
  detail::MlEnd ml_end;  // celc_ml's lines, celc_acc's start
  bool have_ml = false;
  auto getMl = [&]() -> const SolverResult& {
    if (!have_ml) {
      const bool npt_start = detail::nptStartApplies(obs, motion, options.ml);
      ml = detail::solveCelcMl(obs, motion, getLinear(), npt_start ? &getNpt() : nullptr, options, frames,
                               seeds.refine_events, &ml_end);
      have_ml = true;
    }
    return ml;
  };
  for (Method m : methods) {
    switch (m) {
      case Method::Celc: out.push_back(getLinear()); break;
      case Method::Ce3lc:
        out.push_back(detail::solveCe3lc(obs, motion, options.linear, frames, false));
        break;
      case Method::Npt: out.push_back(getNpt()); break;
      case Method::CelcAcc:
        getMl();
        out.push_back(detail::solveCelcAcc(obs, motion, getLinear(), ml, ml_end, options, frames, seeds.linear_rows,
                                           seeds.refine_events));
        break;
      case Method::CelcMl: out.push_back(getMl()); break;
      case Method::CelcOpt: {
        const SolverResult& init = getLinear();
        out.push_back(celcOptCanStart(init) ? solveCelcOpt(obs, motion, init, options, frames, seeds) : init);
        break;
      }
    }
  }
  const UncertaintyOptions& u = options.uncertainty;
  // The events' terms of the bound, formed once for every direction asked about.
  std::optional<DirectionTerms> direction_terms;
  auto terms = [&]() -> const DirectionTerms& {
    if (!direction_terms) direction_terms.emplace(obs, motion, u.max_events);
    return *direction_terms;
  };
  // The linear methods' ambiguous verdicts checked against the events' bound.
  std::vector<double> sigma_floor_deg(out.size(), 0.0);
  for (size_t i = 0; i < out.size(); ++i)
    if (options.linear.answer_when_observable && (methods[i] == Method::Celc || methods[i] == Method::Ce3lc) &&
        out[i].degeneracy == Degeneracy::NullspaceNotUnique)
      sigma_floor_deg[i] = answerIfObservable(obs, motion, options.linear, terms(), frames, out[i]);
  // Answers that put the clusters' lines behind the camera: their floor is
  // applied last, so that they still witness with their Fisher sigma.
  std::vector<bool> behind(out.size(), false);
  if (u.enabled && u.cheiral_min > 0.0)
    for (size_t i = 0; i < out.size(); ++i) {
      const bool celc_family = methods[i] == Method::Celc || methods[i] == Method::CelcOpt ||
                               methods[i] == Method::CelcMl;
      behind[i] = celc_family && out[i].ok() &&
                  std::abs(detail::resolveSign(obs, motion, out[i].v, frames).margin) < u.cheiral_min;
    }
  auto floorBehind = [&]() {
    for (size_t i = 0; i < out.size(); ++i)
      if (behind[i] && out[i].sigma_deg < kRandomDirectionRmsDeg) {
        out[i].sigma_deg = kRandomDirectionRmsDeg;
        out[i].sigma_rule = "behind_camera";
      }
    return out;
  };
  // The model-error budget, formed once for every direction asked about.
  std::optional<ErrorBudget> budget;
  auto budgetDeg = [&](const Vec3& v) {
    if (!budget) budget.emplace(obs, motion, u);
    return budget->sources() == 0 ? 0.0 : budget->sigmaDeg(terms(), v);
  };
  // The Fisher value times `scale` and the budget in quadrature.
  auto sigmaOf = [&](SolverResult& r, double scale) {
    r.sigma_fisher_deg = terms().sigmaDeg(r.v, scale);
    r.sigma_budget_deg = budgetDeg(r.v);
    r.sigma_deg = std::isnan(r.sigma_budget_deg) ? INFINITY : std::hypot(r.sigma_fisher_deg, r.sigma_budget_deg);
  };
  // What every method shares (the window's verdict), and each estimate's
  // uncertainty at its own direction.
  for (size_t i = 0; i < out.size(); ++i) {
    SolverResult& r = out[i];
    r.parallax = window.parallax;
    r.n_lines = window.n_lines;
    // celc_acc's accelerating answer has its own spread (celc_acc.hpp): the
    // bound assumes a constant v. Its constant-velocity answer is celc_ml's.
    const bool own_sigma = methods[i] == Method::CelcAcc && r.acceleration_seen;
    if (own_sigma) {
      if (!r.ok() || !u.enabled) r.sigma_deg = NAN;
      continue;
    }
    r.sigma_deg = NAN;
    if (!r.ok() || !u.enabled) continue;
    double scale = 1.0;
    switch (methods[i]) {
      case Method::Celc: scale = u.scale_celc; break;
      case Method::CelcOpt: scale = u.scale_celc_opt; break;
      case Method::CelcMl: scale = u.scale_celc_ml; break;
      case Method::Ce3lc: scale = u.scale_ce3lc; break;
      case Method::Npt: scale = u.scale_npt; break;
      case Method::CelcAcc: scale = u.scale_celc_ml; break;
    }
    sigmaOf(r, scale);
    if (sigma_floor_deg[i] > r.sigma_deg) {
      r.sigma_deg = sigma_floor_deg[i];
      r.sigma_rule = "ambiguous_nullspace";
    }
  }
  if (!u.enabled || !u.agreement) return floorBehind();
  // The witnesses: the ok estimates of the celc family with their Fisher
  // sigma, and the linear celc estimate when celc itself was not asked for.
  std::vector<SolverResult> witnesses;
  std::vector<bool> witness_linear;
  std::vector<int> witness_of(out.size(), -1);
  bool celc_asked = false;
  for (size_t i = 0; i < out.size(); ++i) {
    const Method m = methods[i];
    celc_asked = celc_asked || m == Method::Celc;
    if ((m != Method::Celc && m != Method::CelcOpt && m != Method::CelcMl) || !out[i].ok() ||
        !std::isfinite(out[i].sigma_deg))
      continue;
    witness_of[i] = static_cast<int>(witnesses.size());
    witnesses.push_back(out[i]);
    witness_linear.push_back(m == Method::Celc);
  }
  if (!celc_asked && have_linear && linear.ok()) {
    SolverResult w = linear;
    sigmaOf(w, u.scale_celc);
    if (std::isfinite(w.sigma_deg)) {
      witnesses.push_back(w);
      witness_linear.push_back(true);
    }
  }
  if (u.witness_rows > 0 && have_linear) {
    // The linear estimate again on another random subset of rows (a seed
    // apart from the estimate's own): its sampling spread.
    LinearOptions subset = options.linear;
    subset.max_rows = u.witness_rows;
    SolverResult w = detail::solveCelcLinear(obs, motion, subset, frames, false, seeds.linear_rows ^ kWitnessSeed);
    if (w.ok()) {
      sigmaOf(w, u.scale_celc);
      if (std::isfinite(w.sigma_deg)) {
        witnesses.push_back(w);
        witness_linear.push_back(true);
      }
    }
  }
  // The witnesses assume a constant velocity: celc_acc's accelerating answer
  // is not held to them.
  for (size_t i = 0; i < out.size(); ++i) {
    if (!out[i].ok() || !std::isfinite(out[i].sigma_deg)) continue;
    if (methods[i] == Method::CelcAcc && out[i].acceleration_seen) continue;
    const bool refined =
        methods[i] == Method::CelcOpt || methods[i] == Method::CelcMl || methods[i] == Method::CelcAcc;
    std::vector<bool> counts(witnesses.size(), true);
    if (refined && !u.linear_witness_refined)
      for (size_t j = 0; j < witnesses.size(); ++j) counts[j] = !witness_linear[j];
    raiseToDisagreement(out[i], witness_of[i], witnesses, counts);
  }
  return floorBehind();
}

std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options) {
  return solveMethods(obs, motion, methods, options,
                      SampleSeeds{options.linear.seed, options.refine.seed});
}

}  // namespace celc
