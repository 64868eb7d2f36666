// How often `celc solve` answers with its defaults (issue 14 part 3): the
// peer scene's trials (sim/peer_scene.hpp) taken through the path that
// `celc solve` takes for labelled events - normalised pixels and cluster
// labels -> clustersFromLabels -> toObservations -> solveMethods, every option
// at its `celc run` default, the given rate as a constant twist from the first
// event - and the share of trials each method answers (status ok) per cell.
//   build/celc_solve_path_study [--trials N] [--seed S]
// Prints a markdown table (docs/peers.md); about 5 s for 100 trials per cell.
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
  std::printf(" celc nullspace_not_unique | celc phi median / 90th pct. [deg] |\n|---|---|");
  for (size_t i = 0; i <= defaults.methods.size() + 1; ++i) std::printf("---|");
  std::printf("\n");
  for (const Cell& cell : cells) {
    PeerSceneOptions o;
    o.speed = cell.speed_m_s;
    o.event_noise_px = cell.sigma_px;
    o.events_per_line = cell.events_per_line;
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    std::vector<int> ok(defaults.methods.size(), 0);
    int generated = 0, ambiguous = 0;
    std::vector<double> celc_phi_deg;  // celc's ok trials
    for (int t = 0; t < trials; ++t) {
      const PeerSceneTrial tr = generatePeerScene(o, rng);
      if (!tr.ok) continue;
      ++generated;
      const std::vector<SolverResult> res = solveLikeCelcSolve(tr, defaults);
      for (size_t m = 0; m < res.size(); ++m) {
        ok[m] += res[m].ok();
        ambiguous += defaults.methods[m] == Method::Celc && res[m].degeneracy == Degeneracy::NullspaceNotUnique;
        if (defaults.methods[m] == Method::Celc && res[m].ok())
          celc_phi_deg.push_back(directionAngle(tr.true_direction, res[m].v) * 180.0 / M_PI);
      }
    }
    std::printf("| %g, %g, %d | %d |", cell.speed_m_s, cell.sigma_px, cell.events_per_line, generated);
    for (int n : ok) std::printf(" %.2f |", generated > 0 ? static_cast<double>(n) / generated : 0.0);
    std::sort(celc_phi_deg.begin(), celc_phi_deg.end());
    auto quantile = [&](double q) {
      return celc_phi_deg.empty() ? NAN : celc_phi_deg[static_cast<size_t>(q * (celc_phi_deg.size() - 1))];
    };
    std::printf(" %d | %.2f / %.2f |\n", ambiguous, quantile(0.5), quantile(0.9));
    std::fflush(stdout);
  }
  return 0;
}
