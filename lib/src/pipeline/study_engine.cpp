#include "celc/pipeline/study_engine.hpp"

#include <atomic>
#include <stdexcept>

#include "celc/core/parallel.hpp"
#include "celc/eval/metrics.hpp"

namespace celc {

std::mt19937_64 trialRng(std::uint64_t seed, const CellKey& key, int trial) {
  std::vector<std::uint32_t> words{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)};
  words.insert(words.end(), key.begin(), key.end());
  words.push_back(static_cast<std::uint32_t>(trial));
  std::seed_seq seq(words.begin(), words.end());
  return std::mt19937_64(seq);
}

std::vector<MethodOutcome> scoreResults(const std::vector<SolverResult>& results, const Vec3& truth) {
  std::vector<MethodOutcome> out(results.size());
  for (std::size_t m = 0; m < results.size(); ++m) {
    const SolverResult& r = results[m];
    MethodOutcome& o = out[m];
    o.ok = r.ok();
    if (!o.ok) continue;
    const DirectionErrors e = directionErrors(truth, r.v);
    o.eps = e.eps;
    o.phi = e.phi;
    o.phi_sign_agnostic = e.phi_sign_agnostic;
    o.time_us = r.time_us;
    o.sigma_deg = r.sigma_deg;
    o.sigma_rule = r.sigma_rule;
  }
  return out;
}

StudyOutcomes::StudyOutcomes(std::size_t cells, int trials, int methods)
    : cells_(cells), trials_(trials), methods_(methods),
      outcomes_(cells * static_cast<std::size_t>(trials)) {}

const TrialOutcome& StudyOutcomes::trial(std::size_t cell, int trial) const {
  return outcomes_.at(cell * static_cast<std::size_t>(trials_) + static_cast<std::size_t>(trial));
}

TrialOutcome& StudyOutcomes::trial(std::size_t cell, int trial) {
  return outcomes_.at(cell * static_cast<std::size_t>(trials_) + static_cast<std::size_t>(trial));
}

std::vector<MethodOutcome> StudyOutcomes::methodOutcomes(std::size_t cell, int method) const {
  std::vector<MethodOutcome> out;
  out.reserve(static_cast<std::size_t>(trials_));
  for (int t = 0; t < trials_; ++t) out.push_back(trial(cell, t).methods.at(static_cast<std::size_t>(method)));
  return out;
}

StudyOutcomes runStudy(const StudyPlan& plan, const TrialFunction& run_trial,
                       const std::function<void(int, int)>& progress) {
  if (plan.trials < 0 || plan.methods < 0) throw std::invalid_argument("study: negative trial or method count");
  StudyOutcomes outcomes(plan.cells.size(), plan.trials, plan.methods);
  const std::size_t total = plan.cells.size() * static_cast<std::size_t>(plan.trials);
  std::atomic<int> done{0};
  parallelFor(total, plan.threads, [&](std::size_t job) {
    const std::size_t cell = job / static_cast<std::size_t>(plan.trials);
    const int trial = static_cast<int>(job % static_cast<std::size_t>(plan.trials));
    std::mt19937_64 rng = trialRng(plan.seed, plan.cells[cell], trial);
    TrialOutcome outcome = run_trial(cell, trial, rng);
    outcome.methods.resize(static_cast<std::size_t>(plan.methods));  // missing: not ok
    outcomes.trial(cell, trial) = std::move(outcome);
    const int d = ++done;
    if (progress) progress(d, static_cast<int>(total));
  });
  return outcomes;
}

}  // namespace celc
