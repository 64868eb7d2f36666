// Speed of method npt (Gao et al., CVPR 2024) on the peers' scene, and of the
// Cramér-Rao bound, 5 lines x 200 events (published reference: ~50 us per solve).
#include <benchmark/benchmark.h>

#include "celc/eval/crlb.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/npt.hpp"
#include "celc/solver/solver.hpp"

using namespace celc;

namespace {
PeerSceneTrial peerScene(int events_per_line) {
  PeerSceneOptions o;
  o.speed = 2.0;
  o.event_noise_px = 1.0;
  o.events_per_line = events_per_line;
  std::mt19937_64 rng(42);
  return generatePeerScene(o, rng);
}
}  // namespace

// The raw solver (sign-agnostic): per line 6x6 normal matrix and eigen-solve,
// velocity averaging. arg = events per line (5 lines).
static void BM_NptSolve(benchmark::State& state) {
  const auto tr = peerScene(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(solveNpt(tr.observations, tr.given_motion, {}));
}
BENCHMARK(BM_NptSolve)->Arg(200)->Arg(1000)->Unit(benchmark::kMicrosecond);

// npt as the pipeline runs it: window checks, solve, cheirality sign.
static void BM_NptMethodWithSign(benchmark::State& state) {
  const auto tr = peerScene(200);
  for (auto _ : state)
    benchmark::DoNotOptimize(solveMethods(tr.observations, tr.given_motion, {Method::Npt}, {}));
}
BENCHMARK(BM_NptMethodWithSign)->Unit(benchmark::kMicrosecond);

// The CRLB of one trial (5 lines x 200 events).
static void BM_CrlbFiveLines(benchmark::State& state) {
  const auto tr = peerScene(200);
  for (auto _ : state)
    benchmark::DoNotOptimize(
        velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, 1.0));
}
BENCHMARK(BM_CrlbFiveLines)->Unit(benchmark::kMicrosecond);
