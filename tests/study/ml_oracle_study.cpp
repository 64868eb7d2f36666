// Where celc_ml's RMS beyond the Cramér-Rao bound comes from (the peers' accuracy
// target, docs/accuracy.md): the search for the joint cost's global minimum, or
// that minimum itself. The peer study's trials (`celc simulate --study peers
// --trials N`, the same seeding: pipeline/peer_study.hpp) of its 5 x 200
// grid cells at V = 1, 2, 5 m/s and 0.5-2 px, with its solver options; per
// trial celc_ml as the study runs it, then, on one joint problem with
// celc_ml's events and Huber threshold (solver/joint_refine.hpp), a
// refinement to convergence from celc_ml's answer and one from the true
// direction, both from the fitted lines. The lower of the two end points is
// the best minimum known: no search for the cost's minimum can do better
// than choosing it, and where celc_ml's end point is the lower one the
// cost's global minimum is not in the truth's basin. Prints per cell, as RMS
// of the sign-agnostic error over the bound's RMS:
//   celc_ml                   the estimate as the study gives it
//   from truth                the end point of the start at the truth
//   best known minimum        the lower of the two end points
// and the trials where the two end points are more than 1 deg apart:
// "truth lower" (a lower basin that celc_ml's search missed) and "wrong
// basin lower" (the cost prefers a wrong direction on that draw of noise).
//   build/celc_ml_oracle_study [--trials N] [--seed S]      (defaults 500, 1)
// About 10 s for 500 trials per cell.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "celc/eval/crlb.hpp"
#include "celc/pipeline/peer_study.hpp"
#include "celc/pipeline/study_engine.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"
#include "solver/joint_refine.hpp"
#include "study_args.hpp"

using namespace celc;

namespace {

double rmsOver(const std::vector<double>& x, double bound_rms) {
  double sq = 0.0;
  for (double v : x) sq += v * v;
  return x.empty() ? NAN : std::sqrt(sq / static_cast<double>(x.size())) / bound_rms;
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 500, seed = 1;
  const int status = study::parseStudyArgs(argc, argv, "celc_ml_oracle_study", trials, seed);
  if (status >= 0) return status;
  SolverOptions solver = SolverOptions::paper();  // the paper's preset, as `celc simulate --study peers` takes it
  solver.check_parallax = false;
  std::vector<PeerCell> cells;
  for (const PeerCell& c : peerStudyCells())
    if (c.groups.find("grid") != std::string::npos && c.speed <= 5.0 && c.sigma_px > 0.0) cells.push_back(c);
  constexpr double kDeg = 180.0 / M_PI;
  std::printf("| V [m/s], sigma [px] | trials | bound RMS [deg] | celc_ml | from truth | best known minimum |"
              " truth lower | wrong basin lower |\n|---|---|---|---|---|---|---|---|\n");
  for (const PeerCell& cell : cells) {
    PeerSceneOptions o;
    cell.apply(o);
    std::vector<double> ml_err, truth_err, best_err;
    double bound_sq = 0.0;
    int truth_lower = 0, wrong_lower = 0;
    for (int t = 0; t < trials; ++t) {
      std::mt19937_64 rng = trialRng(static_cast<std::uint64_t>(seed), {peerCellKey(cell)}, t);
      const PeerSceneTrial tr = generatePeerScene(o, rng);
      if (!tr.ok) continue;
      const CrlbResult b = velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, o.event_noise_px);
      const SampleSeeds seeds{rng(), solver.refine.seed};
      const SolverResult ml = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, solver, seeds)[0];
      if (!b.ok || !std::isfinite(b.rms_rad) || !ml.ok()) continue;
      bound_sq += b.rms_rad * b.rms_rad;
      const detail::WindowFrames frames(tr.observations, tr.given_motion);
      detail::JointProblem problem(tr.observations, tr.given_motion, frames, solver.ml.max_events,
                                   solver.refine.balance_clusters, seeds.refine_events, solver.refine.huber_px);
      const int iterations = solver.refine.max_iterations;
      const double tolerance = solver.refine.function_tolerance;
      detail::JointProblem::Result from_ml = problem.refine(problem.start(ml.v), iterations, tolerance);
      // celc_ml's Huber threshold: huber_scale robust scales at its first end point.
      const double scaled = solver.ml.huber_scale * problem.robustScale(from_ml.state);
      if (scaled > solver.refine.huber_px) {
        problem.setLoss(detail::RobustLoss::huber(scaled));
        from_ml = problem.refine(from_ml.state, iterations, tolerance);
      }
      const detail::JointProblem::Result from_truth =
          problem.refine(problem.start(tr.true_direction), iterations, tolerance);
      const double ml_rad = angleBetweenSignAgnostic(ml.v, tr.true_direction);
      const double truth_rad = from_truth.ok ? angleBetweenSignAgnostic(from_truth.state.v, tr.true_direction)
                                             : ml_rad;
      const bool apart = from_truth.ok && from_ml.ok &&
                         angleBetweenSignAgnostic(from_ml.state.v, from_truth.state.v) * kDeg > 1.0;
      const bool truth_is_lower = from_truth.ok && (!from_ml.ok || from_truth.cost < from_ml.cost);
      truth_lower += apart && truth_is_lower;
      wrong_lower += apart && !truth_is_lower;
      ml_err.push_back(ml_rad);
      truth_err.push_back(truth_rad);
      best_err.push_back(truth_is_lower ? truth_rad : ml_rad);
    }
    const double bound_rms = std::sqrt(bound_sq / std::max<size_t>(1, ml_err.size()));
    std::printf("| %g, %g | %zu | %.2f | %.2f | %.2f | %.2f | %d | %d |\n", cell.speed, cell.sigma_px,
                ml_err.size(), bound_rms * kDeg, rmsOver(ml_err, bound_rms), rmsOver(truth_err, bound_rms),
                rmsOver(best_err, bound_rms), truth_lower, wrong_lower);
    std::fflush(stdout);
  }
  return 0;
}
