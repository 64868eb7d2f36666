#pragma once
/// \file study_engine.hpp
/// The Monte-Carlo engine behind `celc simulate` (the paper's sweeps and the
/// peer study): cells x trials x methods.
///
/// A study is a list of cells (a sweep level, a peer-study cell), each run
/// for the same number of random trials; a trial draws its scene and solves
/// it with every method. Trial i of a cell draws from its own generator,
/// seeded from (study seed, the cell's key, i) only, so every method sees the
/// same data and the outcomes do not depend on the thread count, on the order
/// in which trials run, or on the other cells of the study.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "celc/solver/solver.hpp"

namespace celc {

/// A cell's identity for seeding: a few 32-bit words, the same in every run
/// (e.g. a sweep's name hash and the level index, or a hash of the cell's parameters).
using CellKey = std::vector<std::uint32_t>;

/// The generator of trial `trial` of the cell `key`: std::seed_seq over
/// (low word of seed, high word of seed, the key's words..., trial).
std::mt19937_64 trialRng(std::uint64_t seed, const CellKey& key, int trial);

/// What one method did in one trial.
struct MethodOutcome {
  bool ok = false;                 ///< an estimate was scored
  double eps = 0.0;                ///< |v_true - v| (eval/metrics.hpp)
  double phi = 0.0;                ///< [rad]
  double phi_sign_agnostic = 0.0;  ///< min(phi, pi - phi) [rad]
  double time_us = 0.0;            ///< solver time of the method
  double sigma_deg = NAN;          ///< the estimate's standard deviation [deg] (SolverResult)
  std::string sigma_rule;          ///< the rule that raised sigma_deg (SolverResult)
};

/// One trial: an outcome per method (in the study's method order; missing
/// ones count as not ok), and an optional per-trial reference such as the
/// Cramér-Rao bound (NaN when there is none).
struct TrialOutcome {
  std::vector<MethodOutcome> methods;
  double reference = NAN;
  double translation_px = NAN;  ///< the window's D (pipeline/window_policy.hpp) [px], where measured
};

/// Scores every result against the true unit direction: ok results get
/// eps, phi and the sign-agnostic phi; the others stay not ok.
std::vector<MethodOutcome> scoreResults(const std::vector<SolverResult>& results, const Vec3& truth);

struct StudyPlan {
  std::vector<CellKey> cells;  ///< one key per cell, in output order
  int trials = 0;              ///< per cell
  int methods = 0;             ///< outcomes per trial
  std::uint64_t seed = 1;
  int threads = 0;             ///< 0 = every core
};

/// Every trial's outcome, by cell and trial.
class StudyOutcomes {
 public:
  StudyOutcomes(std::size_t cells, int trials, int methods);
  std::size_t cells() const { return cells_; }
  int trials() const { return trials_; }
  int methods() const { return methods_; }
  const TrialOutcome& trial(std::size_t cell, int trial) const;
  TrialOutcome& trial(std::size_t cell, int trial);
  /// One method's outcomes over the cell's trials, in trial order.
  std::vector<MethodOutcome> methodOutcomes(std::size_t cell, int method) const;

 private:
  std::size_t cells_;
  int trials_, methods_;
  std::vector<TrialOutcome> outcomes_;  ///< cell-major
};

/// Runs one trial: the cell's index, the trial's index and its generator.
using TrialFunction = std::function<TrialOutcome(std::size_t cell, int trial, std::mt19937_64& rng)>;

/// Runs every trial of every cell on plan.threads threads. progress(done,
/// total) is called after each trial, from worker threads (may be empty).
StudyOutcomes runStudy(const StudyPlan& plan, const TrialFunction& run_trial,
                       const std::function<void(int, int)>& progress = {});

}  // namespace celc
