// How often `celc solve` answers with its defaults: the
// peer scene's trials (sim/peer_scene.hpp) taken through the path that
// `celc solve` takes for labelled events - normalised pixels and cluster
// labels -> clustersFromLabels -> toObservations -> solveMethods, every option
// at its `celc run` default, the given rate as a constant twist from the first
// event - and the share of trials each method answers (status ok) per cell,
// with the ambiguous nullspaces the linear methods answered.
//   build/celc_solve_path_study [--trials N] [--seed S]
// Prints a markdown table (docs/accuracy.md); about 5 s for 100 trials per cell.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "celc/eval/metrics.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"
#include "study_args.hpp"
#include "../peer_solve_path.hpp"

using namespace celc;

namespace {

struct Cell {
  double speed_m_s, sigma_px;
  int events_per_line;
};

/// The trial solved as `celc solve` solves it (peer_solve_path.hpp).
std::vector<SolverResult> solveLikeCelcSolve(const PeerSceneTrial& tr, const RunConfig& defaults) {
  MotionModel motion = tr.given_motion;
  const WindowObservations obs = test::solvePathObservations(tr, defaults, motion);
  return solveMethods(obs, motion, defaults.methods, defaults.solver, SampleSeeds{defaults.seed, defaults.seed});
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 100, seed = 4242;
  const int status = study::parseStudyArgs(argc, argv, "celc_solve_path_study", trials, seed);
  if (status >= 0) return status;
  const RunConfig defaults;
  const std::vector<Cell> cells{{1, 0.5, 200}, {1, 1, 200}, {1, 2, 200}, {2, 0.5, 200}, {2, 1, 200},
                                {2, 2, 200},   {5, 0.5, 200}, {5, 1, 200}, {5, 2, 200},   {2, 0.5, 20},
                                {2, 1, 20},    {1, 0.5, 20}};
  std::printf("| V [m/s], sigma [px], events per line | trials |");
  for (Method m : defaults.methods) std::printf(" %s |", toString(m).c_str());
  std::printf(" celc nullspace_not_unique | answered ambiguous celc / ce3lc (within 2 sigma_deg) |"
              " celc phi median / 90th pct. [deg] | ce3lc phi median / 90th pct. [deg] |\n|---|---|");
  for (size_t i = 0; i <= defaults.methods.size() + 3; ++i) std::printf("---|");
  std::printf("\n");
  for (const Cell& cell : cells) {
    PeerSceneOptions o;
    o.speed = cell.speed_m_s;
    o.event_noise_px = cell.sigma_px;
    o.events_per_line = cell.events_per_line;
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    std::vector<int> ok(defaults.methods.size(), 0);
    int generated = 0, ambiguous = 0;
    // Ambiguous nullspaces answered (LinearOptions::answer_when_observable),
    // and how many of those within twice their sigma_deg (sign included).
    int answered_celc = 0, answered_ce3lc = 0, answered_within = 0;
    std::vector<double> celc_phi_deg, ce3lc_phi_deg;  // their ok trials
    for (int t = 0; t < trials; ++t) {
      const PeerSceneTrial tr = generatePeerScene(o, rng);
      if (!tr.ok) continue;
      ++generated;
      const std::vector<SolverResult> res = solveLikeCelcSolve(tr, defaults);
      for (size_t m = 0; m < res.size(); ++m) {
        ok[m] += res[m].ok();
        ambiguous += defaults.methods[m] == Method::Celc && res[m].degeneracy == Degeneracy::NullspaceNotUnique;
        const bool linear = defaults.methods[m] == Method::Celc || defaults.methods[m] == Method::Ce3lc;
        if (!linear || !res[m].ok()) continue;
        const double phi_deg = directionAngle(tr.true_direction, res[m].v) * 180.0 / M_PI;
        (defaults.methods[m] == Method::Celc ? celc_phi_deg : ce3lc_phi_deg).push_back(phi_deg);
        if (res[m].message.rfind("ambiguous nullspace", 0) == 0) {
          ++(defaults.methods[m] == Method::Celc ? answered_celc : answered_ce3lc);
          answered_within += phi_deg <= 2.0 * res[m].sigma_deg;
        }
      }
    }
    std::printf("| %g, %g, %d | %d |", cell.speed_m_s, cell.sigma_px, cell.events_per_line, generated);
    for (int n : ok) std::printf(" %.2f |", generated > 0 ? static_cast<double>(n) / generated : 0.0);
    auto quantile = [](std::vector<double> x, double q) {
      std::sort(x.begin(), x.end());
      return x.empty() ? NAN : x[static_cast<size_t>(q * (x.size() - 1))];
    };
    std::printf(" %d | %d / %d (%d) | %.2f / %.2f | %.2f / %.2f |\n", ambiguous, answered_celc, answered_ce3lc,
                answered_within, quantile(celc_phi_deg, 0.5), quantile(celc_phi_deg, 0.9),
                quantile(ce3lc_phi_deg, 0.5), quantile(ce3lc_phi_deg, 0.9));
    std::fflush(stdout);
  }
  return 0;
}
