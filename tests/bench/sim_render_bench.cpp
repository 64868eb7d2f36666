// Generation speed of the rendering event simulator: DAVIS346 (346x260) in front
// of a chessboard, moving at 1 m/s (the scene of config/scenes/davis346_chessboard.yaml).
// Counter `events_per_s`: events generated per second of wall time (target >= 1 M/s on 2 threads).
#include <benchmark/benchmark.h>

#include "celc/geometry/so3.hpp"
#include "celc/sim/render.hpp"
#include "celc/sim/render_sequence.hpp"

using namespace celc;
using namespace celc;

namespace {

void BM_SimRenderChessboardDavis346(benchmark::State& state) {
  CameraModel cam = cameraPreset("davis346");
  cam.distortion = DistortionModel::RadTan;
  cam.coeffs = {-0.05, 0.01, 0.0, 0.0, 0.0};
  PlaneSpec p;
  p.texture = TextureKind::Chessboard;
  p.position = Vec3(0.0, 0.0, 2.5);
  p.rotation = Vec3(0.15, -0.25, 0.05);
  p.square = 0.25;
  p.columns = 24;
  p.rows = 18;
  p.dark = 0.25;
  p.light = 0.75;
  const Scene scene = Scene::build({p}, 0.5, 1);
  TrajectorySpec ts;
  ts.v = Vec3(0.8, 0.3, 0.5196);  // |v| = 1 m/s
  ts.w = Vec3(0.1, -0.2, 0.15);
  const Trajectory tr(ts, 1.0);
  RenderOptions o;
  o.noise_rate = 0.1;
  o.threads = static_cast<int>(state.range(0));
  const double duration = 0.25;  // simulated [s] per iteration
  int64_t events = 0;
  std::vector<SimEvent> ev;
  for (auto _ : state) {
    RenderEventSimulator sim(scene, cam, tr, o);
    ev.clear();
    sim.advanceTo(duration, ev);
    events += static_cast<int64_t>(ev.size());
    benchmark::DoNotOptimize(ev.data());
  }
  state.counters["events_per_s"] =
      benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
  state.counters["events_per_iter"] =
      benchmark::Counter(static_cast<double>(events) / state.iterations());
}
BENCHMARK(BM_SimRenderChessboardDavis346)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
