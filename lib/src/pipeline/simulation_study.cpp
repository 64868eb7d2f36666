#include "celc/pipeline/simulation_study.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "celc/eval/statistics.hpp"
#include "celc/pipeline/study_engine.hpp"
#include "celc/pipeline/window_policy.hpp"

namespace celc {
namespace {

std::vector<double> range(double from, double to, double step) {
  std::vector<double> v;
  for (int i = 0; from + i * step <= to + 1e-9; ++i) v.push_back(from + i * step);
  return v;
}


void meanStd(const std::vector<double>& x, double& m, double& stdev) {
  m = mean(x);
  stdev = sampleStd(x);
}

/// The solver options with the scene's own gyro error, a constant rate
/// error of omega_noise per axis, added in quadrature to sigma_deg's budget.
SolverOptions withSceneBudget(SolverOptions solver, const LineSceneOptions& scene) {
  UncertaintyOptions& u = solver.uncertainty;
  u.gyro_bias_rad_s = std::hypot(u.gyro_bias_rad_s, scene.omega_noise);
  return solver;
}

}  // namespace

const std::vector<Sweep>& paperSweeps() {
  static const std::vector<Sweep> sweeps{
      {"default", "default setting", {0.0}, [](LineSceneOptions&, double) {}},
      {"event_noise", "event noise [px]", range(0.0, 5.0, 0.5),
       [](LineSceneOptions& o, double x) { o.event_noise_px = x; }},
      {"line_noise", "line endpoint noise [px]", range(0.0, 5.0, 0.5),
       [](LineSceneOptions& o, double x) { o.line_noise_px = x; }},
      {"omega_noise", "angular velocity noise [rad/s]", range(0.0, 1.0, 0.1),
       [](LineSceneOptions& o, double x) { o.omega_noise = x; }},
      {"speed", "speed [m/s]", range(0.0, 10.0, 1.0),
       [](LineSceneOptions& o, double x) { o.velocity = Vec3(1.0, 2.0, 0.0).normalized() * x; }},
      {"interval", "time interval [s]", range(0.2, 2.2, 0.2),
       [](LineSceneOptions& o, double x) { o.duration = x; }},
      {"lines", "number of lines", range(2.0, 10.0, 1.0),
       [](LineSceneOptions& o, double x) { o.n_lines = static_cast<int>(std::lround(x)); }},
  };
  return sweeps;
}

const std::vector<Sweep>& extraSweeps() {
  static const std::vector<Sweep> sweeps{
      // rho = |a| Z / (2 V^2), Z the middle of the scene's depths: an
      // acceleration's share of what fixes v (docs/accuracy.md).
      {"acceleration", "rho = |a| Z / (2 V^2) [-]", {0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0},
       [](LineSceneOptions& o, double rho) {
         const double z = 0.5 * (o.z_range[0] + o.z_range[1]);
         o.acceleration = rho * 2.0 * o.velocity.squaredNorm() / z;
       }},
  };
  return sweeps;
}

const std::vector<Sweep>& sigmaSweeps() {
  static const std::vector<Sweep> sweeps{
      {"default", "default setting", {0.0}, [](LineSceneOptions&, double) {}},
      {"event_noise", "event noise [px]", {0.5, 1.0, 4.0},
       [](LineSceneOptions& o, double x) { o.event_noise_px = x; }},
      {"line_noise", "line endpoint noise [px]", {0.5, 4.0},
       [](LineSceneOptions& o, double x) { o.line_noise_px = x; }},
      {"omega_noise", "angular velocity noise [rad/s]", {0.1, 0.3},
       [](LineSceneOptions& o, double x) { o.omega_noise = x; }},
      {"speed", "speed [m/s]", {1.0, 5.0},
       [](LineSceneOptions& o, double x) { o.velocity = Vec3(1.0, 2.0, 0.0).normalized() * x; }},
      {"interval", "time interval [s]", {0.2, 1.0},
       [](LineSceneOptions& o, double x) { o.duration = x; }},
      {"lines", "number of lines", {3.0, 10.0},
       [](LineSceneOptions& o, double x) { o.n_lines = static_cast<int>(std::lround(x)); }},
      // Pure rotation: level = window length [s]; |w| grows with it from 0.3 to 3 rad/s.
      {"pure_rotation", "window [s] (speed 0, |w| 0.3-3 rad/s)", {0.05, 0.2, 0.5, 1.0},
       [](LineSceneOptions& o, double x) {
         o.velocity = Vec3::Zero();
         o.duration = x;
         const double w = 0.3 + 2.7 * (x - 0.05) / 0.95;
         o.omega = Vec3(0.3, -0.5, 0.8).normalized() * w;
       },
       true},
  };
  return sweeps;
}

const Sweep& findSweep(const std::string& name) {
  std::string names;
  for (const auto* list : {&paperSweeps(), &extraSweeps()})
    for (const auto& s : *list) {
      if (s.name == name) return s;
      names += (names.empty() ? "" : ", ") + s.name;
    }
  throw std::invalid_argument("unknown sweep '" + name + "' (expected all or one of: " + names + ")");
}

std::vector<SweepCell> runSweep(const Sweep& sweep, const SimulateConfig& config, int threads,
                                const std::function<void(int, int)>& progress) {
  const int n_levels = static_cast<int>(sweep.levels.size());
  const int n_trials = config.trials;
  const int n_methods = static_cast<int>(config.methods.size());
  std::uint64_t sweep_id = 0;
  for (char ch : sweep.name) sweep_id = sweep_id * 131 + static_cast<unsigned char>(ch);

  StudyPlan plan;
  for (int level = 0; level < n_levels; ++level)
    plan.cells.push_back({static_cast<std::uint32_t>(sweep_id), static_cast<std::uint32_t>(level)});
  plan.trials = n_trials;
  plan.methods = n_methods;
  plan.seed = config.seed;
  plan.threads = threads;
  const StudyOutcomes outcomes = runStudy(
      plan,
      [&](std::size_t level, int, std::mt19937_64& rng) {
        LineSceneOptions scene = config.scene;
        sweep.apply(scene, sweep.levels[level]);
        const LineSceneTrial tr = generateLineScene(scene, rng);
        const SampleSeeds seeds{rng(), config.solver.refine.seed};
        const auto res =
            solveMethods(tr.observations, tr.given_motion, config.methods, withSceneBudget(config.solver, scene), seeds);
        TrialOutcome out;
        out.translation_px = lineTranslationPx(tr.observations, tr.given_motion, 0.0, scene.duration);
        if (tr.true_direction.norm() > 0.5) {
          out.methods = scoreResults(res, tr.true_direction);
        } else if (sweep.score_without_truth) {
          // No true direction (speed 0): an ok result counts with phi = pi
          // (never covered), so the sigma study sees confident estimates.
          out.methods = scoreResults(res, Vec3::UnitZ());
          for (auto& o : out.methods) o.phi = o.eps = M_PI;
        }
        return out;
      },
      progress);

  std::vector<SweepCell> cells;
  for (int level = 0; level < n_levels; ++level) {
    for (int m = 0; m < n_methods; ++m) {
      SweepCell c;
      std::vector<double> sig;
      for (int t = 0; t < n_trials; ++t) {
        const TrialOutcome& trial = outcomes.trial(static_cast<size_t>(level), t);
        if (static_cast<size_t>(m) >= trial.methods.size()) continue;
        const MethodOutcome& o = trial.methods[static_cast<size_t>(m)];
        if (!o.ok) continue;
        c.samples.push_back({o.phi, o.sigma_deg, trial.translation_px, o.sigma_rule});
        sig.push_back(o.sigma_deg);
        if (o.phi <= 2.0 * o.sigma_deg * M_PI / 180.0) ++c.covered_2sigma;
        if (o.sigma_deg < 10.0) ++c.confident_10deg;
      }
      c.sigma_median_deg = median(sig);
      c.sweep = sweep.name;
      c.level = sweep.levels[static_cast<size_t>(level)];
      c.method = config.methods[static_cast<size_t>(m)];
      c.trials = n_trials;
      std::vector<double> eps, phi, agn, time;
      for (const MethodOutcome& o : outcomes.methodOutcomes(static_cast<size_t>(level), m)) {
        if (!o.ok) continue;
        eps.push_back(o.eps);
        phi.push_back(o.phi);
        agn.push_back(o.phi_sign_agnostic);
        time.push_back(o.time_us);
        if (o.phi < M_PI / 2) ++c.sign_right;
      }
      c.n_ok = static_cast<int>(phi.size());
      meanStd(eps, c.eps_mean, c.eps_std);
      meanStd(phi, c.phi_mean, c.phi_std);
      c.phi_median = median(phi);
      c.phi_median_sign_agnostic = median(agn);
      c.time_median_us = median(time);
      cells.push_back(c);
    }
  }
  return cells;
}

std::string sweepCsvHeader() {
  return "sweep,level,method,trials,n_ok,eps_mean,eps_std,phi_mean,phi_std,phi_median";
}

std::string sweepCsvRow(const SweepCell& c) {
  std::ostringstream os;
  os.precision(9);
  auto num = [&](double x) {
    if (std::isfinite(x)) os << x;  // empty field when no trial was ok
  };
  os << c.sweep << "," << c.level << "," << toString(c.method) << "," << c.trials << "," << c.n_ok
     << ",";
  num(c.eps_mean);
  os << ",";
  num(c.eps_std);
  os << ",";
  num(c.phi_mean);
  os << ",";
  num(c.phi_std);
  os << ",";
  num(c.phi_median);
  return os.str();
}

}  // namespace celc
