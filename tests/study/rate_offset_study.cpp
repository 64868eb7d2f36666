// What celc_ml's rate-offset search (solver.ml.rate_offset,
// solver/rate_offset.hpp) buys on the peer study's rate-error cells
// (docs/accuracy.md; the study's trials and seeding, pipeline/peer_study.hpp):
// per cell the median / RMS sign-agnostic error [deg] of npt, celc_ml with
// the option off and on, and of a joint refinement given the true offset
// (no estimator has it: the floor the search aims at); how often the offset
// was kept, the median error of the kept offsets [deg/s] and the median time
// per solve [ms] with the option off and on.
//   build/celc_rate_offset_study [--trials N] [--seed S]      (defaults 500, 1; 25 s)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "celc/pipeline/peer_study.hpp"
#include "celc/pipeline/study_engine.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"
#include "solver/joint_refine.hpp"
#include "study_args.hpp"

using namespace celc;

namespace {

constexpr double kDeg = 180.0 / M_PI;

double median(std::vector<double> x) {
  if (x.empty()) return NAN;
  std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(x.size() / 2), x.end());
  return x[x.size() / 2];
}
double rms(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v * v;
  return x.empty() ? NAN : std::sqrt(s / static_cast<double>(x.size()));
}

// The joint refinement from v with the true offset applied to the given gyro.
double refinedWithTrueOffset(const PeerSceneTrial& tr, const Vec3& v, const SolverOptions& solver,
                             std::uint64_t event_seed) {
  const double tref = tr.given_motion.referenceTime();
  const MotionModel motion = tr.given_motion.withOmegaOffset(tr.true_omega - tr.given_motion.meanOmega(tref, tref + 0.1));
  const detail::WindowFrames frames(tr.observations, motion);
  detail::JointProblem p(tr.observations, motion, frames, solver.ml.max_events, solver.refine.balance_clusters,
                         event_seed, solver.refine.huber_px);
  const auto r = p.refine(p.start(v), solver.refine.max_iterations, solver.refine.function_tolerance);
  return r.ok ? angleBetweenSignAgnostic(r.state.v, tr.true_direction) * kDeg : NAN;
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 500, seed = 1;
  const int status = study::parseStudyArgs(argc, argv, "celc_rate_offset_study", trials, seed);
  if (status >= 0) return status;
  SolverOptions off = SolverOptions::paper();  // the paper's preset, as `celc simulate --study peers` takes it
  off.check_parallax = false;
  SolverOptions on = off;
  on.ml.rate_offset = true;
  std::printf("| rate error [deg/s] | trials | npt | celc_ml | celc_ml, rate_offset | with the true offset | "
              "offset kept | kept offset's error [deg/s] | time off / on [ms] |\n"
              "|---|---|---|---|---|---|---|---|---|\n");
  for (const PeerCell& cell : peerStudyCells()) {
    if (cell.groups.find("omega") == std::string::npos) continue;
    PeerSceneOptions o;
    cell.apply(o);
    std::vector<double> npt_e, off_e, on_e, truth_e, offset_e, t_off, t_on;
    int kept = 0;
    for (int t = 0; t < trials; ++t) {
      std::mt19937_64 rng = trialRng(static_cast<std::uint64_t>(seed), {peerCellKey(cell)}, t);
      const PeerSceneTrial tr = generatePeerScene(o, rng);
      if (!tr.ok) continue;
      const SampleSeeds seeds{rng(), off.refine.seed};
      const auto a = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl, Method::Npt}, off, seeds);
      const auto b = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, on, seeds);
      if (a[1].ok()) npt_e.push_back(angleBetweenSignAgnostic(a[1].v, tr.true_direction) * kDeg);
      if (!a[0].ok() || !b[0].ok()) continue;
      off_e.push_back(angleBetweenSignAgnostic(a[0].v, tr.true_direction) * kDeg);
      on_e.push_back(angleBetweenSignAgnostic(b[0].v, tr.true_direction) * kDeg);
      t_off.push_back(a[0].time_us / 1000.0);
      t_on.push_back(b[0].time_us / 1000.0);
      const double truth = refinedWithTrueOffset(tr, a[0].v, off, seeds.refine_events);
      if (std::isfinite(truth)) truth_e.push_back(truth);
      double d[3];
      if (std::sscanf(b[0].message.c_str(), "rate offset (%lf, %lf, %lf)", &d[0], &d[1], &d[2]) == 3) {
        ++kept;
        const double tref = tr.given_motion.referenceTime();
        const Vec3 true_offset = (tr.true_omega - tr.given_motion.meanOmega(tref, tref + 0.1)) * kDeg;
        offset_e.push_back((Vec3(d[0], d[1], d[2]) - true_offset).norm());
      }
    }
    std::printf("| %g | %zu | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %d | %.2f | %.2f / %.2f |\n",
                cell.omega_error_deg_s, off_e.size(), median(npt_e), rms(npt_e), median(off_e), rms(off_e),
                median(on_e), rms(on_e), median(truth_e), rms(truth_e), kept, median(offset_e), median(t_off),
                median(t_on));
    std::fflush(stdout);
  }
  return 0;
}
