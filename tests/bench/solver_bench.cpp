// Solver speed on the paper's default scene (5 lines, 2 px noise) and the
// peers' scene. Benchmarks time the solvers' defaults, the options of
// `celc run` and `celc solve`; the `Paper` variants time the paper's preset
// (SolverOptions::paper()), what `celc simulate` runs.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "celc/sim/line_scene.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"
#include "solver/ce3lc.hpp"
#include "solver/celc_linear.hpp"
#include "solver/constraint_rows.hpp"
#include "solver/irls_kernel.hpp"
#include "solver/robust_nullspace.hpp"

using namespace celc;

namespace {
LineSceneTrial scene(int events_per_line) {
  LineSceneOptions o;
  o.events_per_line = events_per_line;
  std::mt19937_64 rng(42);
  return generateLineScene(o, rng);
}

// 16 trials of the peers' scene (V = 2 m/s, 1 px) with 5 lines of
// events_per_line events: the time of a solve depends on the trial.
std::vector<PeerSceneTrial> peerTrials(int events_per_line) {
  PeerSceneOptions o;
  o.events_per_line = events_per_line;
  std::vector<PeerSceneTrial> trials;
  std::mt19937_64 rng(42);
  while (trials.size() < 16) {
    auto tr = generatePeerScene(o, rng);
    if (tr.ok) trials.push_back(std::move(tr));
  }
  return trials;
}

std::vector<detail::ConstraintRow> rowsOf(const LineSceneTrial& tr) {
  std::vector<detail::ConstraintRow> rows;
  for (const auto& c : tr.observations.clusters) {
    const auto frame = makeClusterFrame(c, tr.given_motion);
    for (size_t k = 0; k < c.size(); ++k)
      rows.push_back(detail::celcRow(frame, tr.given_motion, c.times[k], c.bearings[k]));
  }
  return rows;
}
}  // namespace

// The robust nullspace (IRLS) alone on 1000 prebuilt rows, packed as the
// CELC solver builds them (BM_PackRows1000: packing rows built apart).
static void BM_CelcLinearSolve1000Rows(benchmark::State& state) {
  const detail::PackedRows rows(rowsOf(scene(200)));
  const LinearOptions opt;
  int iterations = 0;
  for (auto _ : state) {
    const auto sol = detail::robustNullspace(rows, opt);
    iterations = sol.iterations;
    benchmark::DoNotOptimize(sol);
  }
  state.counters["irls_iterations"] = iterations;
}
BENCHMARK(BM_CelcLinearSolve1000Rows)->Unit(benchmark::kMicrosecond);

// Its parts: packing the rows once, and one IRLS pass over them.
static void BM_PackRows1000(benchmark::State& state) {
  const auto rows = rowsOf(scene(200));
  for (auto _ : state) benchmark::DoNotOptimize(detail::PackedRows(rows));
}
BENCHMARK(BM_PackRows1000)->Unit(benchmark::kMicrosecond);

// One fused IRLS pass; the argument is events per line (5 lines: 200 -> 1000 rows).
static void BM_HuberPass(benchmark::State& state) {
  const detail::PackedRows rows(rowsOf(scene(static_cast<int>(state.range(0)))));
  const Vec3 v = Vec3(1.0, 2.0, 0.1).normalized();
  for (auto _ : state) benchmark::DoNotOptimize(detail::weightedSums(rows, v, detail::RobustLoss::huber(1e-3)));
}
BENCHMARK(BM_HuberPass)->Arg(40)->Arg(200)->Arg(2000)->Unit(benchmark::kMicrosecond);

// Building the 1000 rows (rotations, left Jacobians, transfer matrices).
static void BM_CelcBuildRows1000(benchmark::State& state) {
  const auto tr = scene(200);
  for (auto _ : state) benchmark::DoNotOptimize(rowsOf(tr));
}
BENCHMARK(BM_CelcBuildRows1000)->Unit(benchmark::kMicrosecond);

// The whole CELC linear method: checks, rows, IRLS, sign.
static void BM_CelcLinearMethod1000Events(benchmark::State& state) {
  const auto tr = scene(200);
  for (auto _ : state)
    benchmark::DoNotOptimize(solveCelcLinear(tr.observations, tr.given_motion, {}));
}
BENCHMARK(BM_CelcLinearMethod1000Events)->Unit(benchmark::kMicrosecond);

// The CELC linear method as the dispatcher (solveMethods) runs it, the timing
// target: the clusters' frames, the rows, the IRLS and the sign test; the
// window checks, shared by all methods, are measured apart
// (BM_WindowChecks1000Events). arg = events per line, 5 lines.
// Paper's scene: constant twist, |w| T = 1 rad, 2 px noise.
// The CELC linear method as the dispatcher runs it (frames, rows, IRLS, sign).
static void timeCelcLinear(benchmark::State& state, const WindowObservations& obs, const MotionModel& motion,
                           const LinearOptions& opt) {
  int ok = 0, iterations = 0;
  for (auto _ : state) {
    const detail::WindowFrames frames(obs, motion);
    const auto r = detail::solveCelcLinear(obs, motion, opt, frames, false, opt.seed);
    ok = r.ok();
    iterations = r.iterations;
    benchmark::DoNotOptimize(r);
  }
  state.counters["ok"] = ok;
  state.counters["irls_iterations"] = iterations;
}

static void BM_CelcLinear(benchmark::State& state) {
  const auto tr = scene(static_cast<int>(state.range(0)));
  timeCelcLinear(state, tr.observations, tr.given_motion, LinearOptions{});
}
BENCHMARK(BM_CelcLinear)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

static void BM_CelcLinearPaper(benchmark::State& state) {
  const auto tr = scene(static_cast<int>(state.range(0)));
  timeCelcLinear(state, tr.observations, tr.given_motion, SolverOptions::paper().linear);
}
BENCHMARK(BM_CelcLinearPaper)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

// The same on the peers' scene (gyro-integrated rotation, V = 2 m/s, 1 px noise).
static void BM_CelcLinearPeers(benchmark::State& state) {
  PeerSceneOptions o;
  o.events_per_line = static_cast<int>(state.range(0));
  std::mt19937_64 rng(42);
  const auto tr = generatePeerScene(o, rng);
  timeCelcLinear(state, tr.observations, tr.given_motion, LinearOptions{});
}
BENCHMARK(BM_CelcLinearPeers)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

// The same cycling over 16 trials of the peers' scene (the IRLS's iteration
// count, and so the time, depends on the trial): the mean time per solve, and
// the mean iteration count.
static void timeCelcLinearPeers16(benchmark::State& state, const LinearOptions& opt) {
  const std::vector<PeerSceneTrial> trials = peerTrials(static_cast<int>(state.range(0)));
  size_t i = 0;
  double iterations = 0.0;
  for (auto _ : state) {
    const auto& tr = trials[i++ % trials.size()];
    const detail::WindowFrames frames(tr.observations, tr.given_motion);
    const auto r = detail::solveCelcLinear(tr.observations, tr.given_motion, opt, frames, false, opt.seed);
    iterations += r.iterations;
    benchmark::DoNotOptimize(r);
  }
  state.counters["irls_iterations"] = iterations / static_cast<double>(std::max<size_t>(1, i));
}

static void BM_CelcLinearPeers16(benchmark::State& state) { timeCelcLinearPeers16(state, LinearOptions{}); }
BENCHMARK(BM_CelcLinearPeers16)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

// The same under the paper's preset: one start, Huber only.
static void BM_CelcLinearPeers16Paper(benchmark::State& state) {
  timeCelcLinearPeers16(state, SolverOptions::paper().linear);
}
BENCHMARK(BM_CelcLinearPeers16Paper)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

// The same with the Tukey stage alone (the paper's preset with
// solver.linear.tukey_k 3): its extra IRLS passes without the global start.
static void BM_CelcLinearPeers16Tukey(benchmark::State& state) {
  LinearOptions opt = SolverOptions::paper().linear;
  opt.tukey_k = 3.0;
  timeCelcLinearPeers16(state, opt);
}
BENCHMARK(BM_CelcLinearPeers16Tukey)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

// celc_ml on the peers' scene (V = 2 m/s, 1 px noise), as solveMethods runs
// it: its linear and npt starts, the line profile's screen, the joint
// refinements. Cycles over 16 trials (the time depends on the trial);
// arg = events per line, 5 lines. The time column includes the window's
// uncertainty (sigma_deg, the witnesses); method_median_us is the method
// alone. BM_CelcMlPeers: the defaults (`celc solve`'s options);
// BM_CelcMlPeersPaper: the paper's preset, as the peer study runs it
// (target: median <= 1 ms at 200 events per line, <= 0.3 ms at 20).
static void timeCelcMlPeers(benchmark::State& state, SolverOptions opt) {
  const std::vector<PeerSceneTrial> trials = peerTrials(static_cast<int>(state.range(0)));
  opt.check_parallax = false;  // as the peer study runs it
  size_t i = 0;
  std::vector<double> method_us;
  for (auto _ : state) {
    const auto& tr = trials[i++ % trials.size()];
    const auto r = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, opt);
    method_us.push_back(r.front().time_us);
    benchmark::DoNotOptimize(r);
  }
  // The method's own time (SolverResult::time_us, its starts included and
  // the window's uncertainty not), the figure the peer study's time column
  // and the timing target give: median over the iterations [us].
  if (!method_us.empty()) {
    const auto mid = method_us.begin() + static_cast<std::ptrdiff_t>(method_us.size() / 2);
    std::nth_element(method_us.begin(), mid, method_us.end());
    state.counters["method_median_us"] = *mid;
  }
}
static void BM_CelcMlPeers(benchmark::State& state) { timeCelcMlPeers(state, SolverOptions{}); }
BENCHMARK(BM_CelcMlPeers)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

static void BM_CelcMlPeersPaper(benchmark::State& state) { timeCelcMlPeers(state, SolverOptions::paper()); }
BENCHMARK(BM_CelcMlPeersPaper)->Arg(20)->Arg(200)->Unit(benchmark::kMicrosecond);

// CE3LC itself (5 clusters, 15 rows) with its cluster frames; the window
// checks are measured apart.
static void BM_Ce3lc5Lines(benchmark::State& state) {
  const auto tr = scene(200);
  const LinearOptions opt;
  for (auto _ : state) {
    const detail::WindowFrames frames(tr.observations, tr.given_motion);
    benchmark::DoNotOptimize(detail::solveCe3lc(tr.observations, tr.given_motion, opt, frames, false));
  }
}
BENCHMARK(BM_Ce3lc5Lines)->Unit(benchmark::kMicrosecond);

// The window checks shared by all methods (usable clusters, parallax).
static void BM_WindowChecks1000Events(benchmark::State& state) {
  const auto tr = scene(200);
  for (auto _ : state) benchmark::DoNotOptimize(checkWindow(tr.observations, tr.given_motion, {}));
}
BENCHMARK(BM_WindowChecks1000Events)->Unit(benchmark::kMicrosecond);

// All methods on one window with the defaults (sigma_deg with its
// model-error budget), and under the paper's preset as `celc simulate` runs
// them (an empty budget, as for a trial without gyro noise).
static void BM_AllMethodsOneWindow(benchmark::State& state) {
  const auto tr = scene(200);
  for (auto _ : state)
    benchmark::DoNotOptimize(solveMethods(tr.observations, tr.given_motion, allMethods(), SolverOptions{}));
}
BENCHMARK(BM_AllMethodsOneWindow)->Unit(benchmark::kMillisecond);

static void BM_AllMethodsOneWindowPaper(benchmark::State& state) {
  const auto tr = scene(200);
  SolverOptions paper = SolverOptions::paper();
  paper.uncertainty.clearBudget();
  for (auto _ : state)
    benchmark::DoNotOptimize(solveMethods(tr.observations, tr.given_motion, allMethods(), paper));
}
BENCHMARK(BM_AllMethodsOneWindowPaper)->Unit(benchmark::kMillisecond);

// Refinement of v alone (Ceres) from the linear estimate; arg = events.
static void BM_RefineVelocity(benchmark::State& state) {
  const auto tr = scene(static_cast<int>(state.range(0)) / 5);
  const auto init = solveCelcLinear(tr.observations, tr.given_motion, {});
  for (auto _ : state)
    benchmark::DoNotOptimize(refineVelocity(tr.observations, tr.given_motion, init.v, false, {}));
}
BENCHMARK(BM_RefineVelocity)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

// Joint refinement of v and every cluster's l1, l3 (maximum likelihood).
static void BM_RefineJoint(benchmark::State& state) {
  const auto tr = scene(static_cast<int>(state.range(0)) / 5);
  const auto init = solveCelcLinear(tr.observations, tr.given_motion, {});
  for (auto _ : state)
    benchmark::DoNotOptimize(refineVelocity(tr.observations, tr.given_motion, init.v, true, {}));
}
BENCHMARK(BM_RefineJoint)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);
