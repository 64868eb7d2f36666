#pragma once
/// \file simulation_study.hpp
/// The paper's simulation study (Sec. 5.1, Figs. 3 and 4): sweeps of one
/// parameter of the line scene around the default setting, many random
/// trials per level, per method the trials whose status is ok and the mean /
/// std of eps = |v_gt - v_est| and phi = acos(v_gt . v_est) [rad].
/// Trial i of level j of a sweep draws from a seed derived from (seed, sweep,
/// j, i) only, so results do not depend on the thread count.
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "celc/config/config.hpp"

namespace celc {

struct Sweep {
  std::string name;        ///< e.g. "event_noise"
  std::string parameter;   ///< axis label with unit, e.g. "event noise [px]"
  std::vector<double> levels;
  /// Sets the swept parameter of the scene to a level.
  std::function<void(LineSceneOptions&, double)> apply;
  /// Trials without a true direction (speed 0) are scored: an ok result
  /// counts with phi = eps = pi (the sigma study's pure rotation). Else they
  /// count as not ok, as in the paper's speed sweep.
  bool score_without_truth = false;
};

/// The paper's sweeps: event_noise, line_noise, omega_noise, speed, interval,
/// lines; plus `default`, the default setting as a single level.
const std::vector<Sweep>& paperSweeps();
/// Sweeps beyond the paper's, run only when named (not in `all`):
/// `acceleration`, the paper's default scene with a constant acceleration
/// of rho = |a| Z / (2 V^2) = 0 .. 30 (Z the middle of its depths) in a
/// direction drawn per trial (LineSceneOptions::acceleration).
const std::vector<Sweep>& extraSweeps();
/// Looks a sweep up by name (the paper's and the extra ones); throws
/// std::invalid_argument listing the names.
const Sweep& findSweep(const std::string& name);
/// The settings of the uncertainty study (`celc simulate --study sigma`):
/// the default and a few levels of each paper sweep, plus `pure_rotation`
/// (speed 0; |w| 0.3-3 rad/s; windows 0.05-1 s).
const std::vector<Sweep>& sigmaSweeps();

/// One row of `<sweep>.csv`.
struct SweepCell {
  std::string sweep;
  double level = 0.0;
  Method method = Method::Celc;
  int trials = 0;
  int n_ok = 0;
  double eps_mean = 0.0, eps_std = 0.0;
  double phi_mean = 0.0, phi_std = 0.0, phi_median = 0.0;
  double phi_median_sign_agnostic = 0.0;
  double time_median_us = 0.0;  ///< median solver time of the ok trials
  int sign_right = 0;           ///< ok trials with phi < pi/2
  /// ok trials with phi <= 2 sigma_deg (the calibration of the uncertainty),
  /// and ok trials with sigma_deg below 10 deg.
  int covered_2sigma = 0;
  int confident_10deg = 0;
  double sigma_median_deg = NAN;  ///< median sigma_deg of the ok trials
  /// Per ok trial: phi [rad], sigma_deg, the trial's D [px] and the rule that
  /// raised sigma_deg (the sigma study's per-trial table).
  struct SigmaSample {
    double phi = 0.0, sigma_deg = NAN, translation_px = NAN;
    std::string sigma_rule;
  };
  std::vector<SigmaSample> samples;
};

/// Runs every level of a sweep with `threads` workers (0 = all cores).
/// `progress(done, total)` is called from worker threads (may be empty).
std::vector<SweepCell> runSweep(const Sweep& sweep, const SimulateConfig& config, int threads,
                                const std::function<void(int, int)>& progress = {});

/// CSV header and row of the DESIGN.md contract.
std::string sweepCsvHeader();
std::string sweepCsvRow(const SweepCell& cell);

}  // namespace celc
