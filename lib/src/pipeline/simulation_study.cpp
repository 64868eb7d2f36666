#include "celc/pipeline/simulation_study.hpp"

#include "celc/eval/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace celc {
namespace {

std::vector<double> range(double from, double to, double step) {
  std::vector<double> v;
  for (int i = 0; from + i * step <= to + 1e-9; ++i) v.push_back(from + i * step);
  return v;
}


void meanStd(const std::vector<double>& x, double& m, double& stdev) {
  m = eval::mean(x);
  stdev = eval::sampleStd(x);
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

const Sweep& findSweep(const std::string& name) {
  std::string names;
  for (const auto& s : paperSweeps()) {
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
  const int total = n_levels * n_trials;
  std::uint64_t sweep_id = 0;
  for (char ch : sweep.name) sweep_id = sweep_id * 131 + static_cast<unsigned char>(ch);

  struct Outcome {
    bool ok = false;
    double eps = 0, phi = 0, phi_agn = 0, time_us = 0;
  };
  std::vector<Outcome> outcomes(static_cast<size_t>(total) * n_methods);
  std::atomic<int> next{0}, done{0};
  auto worker = [&]() {
    for (int job = next++; job < total; job = next++) {
      const int level = job / n_trials, trial = job % n_trials;
      LineSceneOptions scene = config.scene;
      sweep.apply(scene, sweep.levels[static_cast<size_t>(level)]);
      std::seed_seq seq{static_cast<std::uint32_t>(config.seed), static_cast<std::uint32_t>(config.seed >> 32),
                        static_cast<std::uint32_t>(sweep_id), static_cast<std::uint32_t>(level),
                        static_cast<std::uint32_t>(trial)};
      std::mt19937_64 rng(seq);
      const LineSceneTrial tr = generateLineScene(scene, rng);
      SolverOptions so = config.solver;
      so.linear.seed = rng();
      const auto res = solveMethods(tr.observations, tr.given_motion, config.methods, so);
      for (int m = 0; m < n_methods; ++m) {
        Outcome& o = outcomes[static_cast<size_t>(job) * n_methods + m];
        const SolverResult& r = res[static_cast<size_t>(m)];
        o.ok = r.ok() && tr.true_direction.norm() > 0.5;
        if (!o.ok) continue;
        o.eps = (tr.true_direction - r.v).norm();
        o.phi = angleBetween(tr.true_direction, r.v);
        o.phi_agn = std::min(o.phi, M_PI - o.phi);
        o.time_us = r.time_us;
      }
      const int d = ++done;
      if (progress) progress(d, total);
    }
  };
  const int n_threads = std::max(1, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (int t = 1; t < n_threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();

  std::vector<SweepCell> cells;
  for (int level = 0; level < n_levels; ++level) {
    for (int m = 0; m < n_methods; ++m) {
      SweepCell c;
      c.sweep = sweep.name;
      c.level = sweep.levels[static_cast<size_t>(level)];
      c.method = config.methods[static_cast<size_t>(m)];
      c.trials = n_trials;
      std::vector<double> eps, phi, agn, time;
      for (int trial = 0; trial < n_trials; ++trial) {
        const Outcome& o = outcomes[static_cast<size_t>(level * n_trials + trial) * n_methods + m];
        if (!o.ok) continue;
        eps.push_back(o.eps);
        phi.push_back(o.phi);
        agn.push_back(o.phi_agn);
        time.push_back(o.time_us);
        if (o.phi < M_PI / 2) ++c.sign_right;
      }
      c.n_ok = static_cast<int>(phi.size());
      meanStd(eps, c.eps_mean, c.eps_std);
      meanStd(phi, c.phi_mean, c.phi_std);
      c.phi_median = eval::median(phi);
      c.phi_median_sign_agnostic = eval::median(agn);
      c.time_median_us = eval::median(time);
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
