// What a constant-velocity solver makes of an accelerating camera, and what
// celc_acc (which models the acceleration) makes of it: the peer scene
// (sim/peer_scene.hpp) with a constant acceleration a in a random
// direction, v the velocity at the window's middle (its mean over the
// window, the truth), solved by solveMethods with `celc run`'s default
// solver options and the exact rotation.
//
// Why the ratio rho = |a| Z / (2 V^2) (Z = 4 m, the depths' middle): the
// direction of v reaches the image lines only at second order in time. Under
// a constant v a line's image l(tau) = m - tau (v x d) is linear in tau
// (homogeneous coordinates); the first-order motion is explained by any v
// with the line's own depth, and what fixes v is the curvature of that motion,
// of size f (V T / Z)^2. An acceleration adds f |a| T^2 / (2 Z) at the same
// order, so the bias should depend on their ratio, rho, and not on T.
// The cells vary T at one V (same a) and V at one T (same rho).
// The last column, celc_acc+imu, is celc_acc given an accelerometer's
// reading of the window (WindowObservations::accelerometer): the true a
// plus a bias of N(0, 0.05) m/s^2 per axis, with the sigma `celc run` gives
// it (pipeline/accelerometer.hpp: sqrt(2) x motion.accel_bias_m_s2).
//   build/celc_acceleration_study [--trials N] [--seed S]
// Prints a markdown table of the median phi [deg] per method (docs/accuracy.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "celc/pipeline/accelerometer.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"
#include "study_args.hpp"

using namespace celc;

namespace {

constexpr double kMidDepth = 4.0;  // [m], the middle of the peer scene's 2-6 m

struct Cell {
  double speed_m_s, duration_s, rho;
};

double median(std::vector<double> x) {
  if (x.empty()) return NAN;
  const size_t h = x.size() / 2;
  std::nth_element(x.begin(), x.begin() + static_cast<long>(h), x.end());
  return x[h];
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 100, seed = 31;
  const int status = study::parseStudyArgs(argc, argv, "celc_acceleration_study", trials, seed);
  if (status >= 0) return status;
  const RunConfig defaults;
  // `celc run`'s methods (the paper's five and celc_acc, which models the acceleration).
  const std::vector<Method> methods = defaults.methods;
  const double bias = AccelerometerOptions{}.bias_m_s2;
  std::vector<Cell> cells;
  for (double rho : {0.0, 0.03, 0.1, 0.3, 1.0}) {
    for (double T : {0.25, 0.5, 1.0}) cells.push_back({2.0, T, rho});  // one V: a the same, T varies
    cells.push_back({1.0, 0.5, rho});                                  // one T: rho the same, a and V vary
  }
  std::printf("| rho | V [m/s] | T [s] | a [m/s^2] | trials |");
  for (Method m : methods) std::printf(" %s |", toString(m).c_str());
  std::printf(" celc_acc+imu |\n|---|---|---|---|---|");
  for (size_t i = 0; i <= methods.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const Cell& cell : cells) {
    PeerSceneOptions o;
    o.speed = cell.speed_m_s;
    o.duration = cell.duration_s;
    o.event_noise_px = 0.5;
    o.acceleration = cell.rho * 2.0 * cell.speed_m_s * cell.speed_m_s / kMidDepth;
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed)), imu_rng(static_cast<std::uint64_t>(seed) + 1);
    std::normal_distribution<double> bias_draw(0.0, bias);
    std::vector<std::vector<double>> phi(methods.size() + 1);
    int generated = 0;
    for (int t = 0; t < trials; ++t) {
      const PeerSceneTrial tr = generatePeerScene(o, rng);
      if (!tr.ok) continue;
      ++generated;
      const std::vector<SolverResult> res = solveMethods(tr.observations, tr.given_motion, methods,
                                                         defaults.solver, SampleSeeds{defaults.seed, defaults.seed});
      for (size_t m = 0; m < res.size(); ++m)
        phi[m].push_back(res[m].ok() ? angleBetween(tr.true_direction, res[m].v) * 180.0 / M_PI : 180.0);
      WindowObservations with_imu = tr.observations;
      with_imu.accelerometer.valid = true;
      with_imu.accelerometer.a = tr.true_acceleration + Vec3(bias_draw(imu_rng), bias_draw(imu_rng), bias_draw(imu_rng));
      with_imu.accelerometer.sigma = std::sqrt(2.0) * bias;
      const SolverResult acc = solveMethods(with_imu, tr.given_motion, {Method::CelcAcc}, defaults.solver,
                                            SampleSeeds{defaults.seed, defaults.seed})
                                   .front();
      phi.back().push_back(acc.ok() ? angleBetween(tr.true_direction, acc.v) * 180.0 / M_PI : 180.0);
    }
    std::printf("| %g | %g | %g | %.3g | %d |", cell.rho, cell.speed_m_s, cell.duration_s, o.acceleration, generated);
    for (const std::vector<double>& p : phi) std::printf(" %.2f |", median(p));
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}
