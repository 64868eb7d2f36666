// Reader throughput (events/s, one core) and the memory of windowed reading.
// Inputs are generated once per process into the temp directory (removed at exit).
// Targets (docs/formats.md): events.txt >= 10 M/s, AEDAT 2.0 >= 50 M/s,
// AEDAT 4.0 LZ4 >= 30 M/s, windowed events.txt peak RSS < 300 MB.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "celc/geometry/camera.hpp"
#include "celc/geometry/undistort.hpp"
#include "celc/io/event_reader.hpp"
#include "celc/io/window_source.hpp"
#include "read_all.hpp"
#include "celc/io/writers.hpp"

namespace {

using namespace celc;

std::vector<Event> benchEvents(std::size_t n) {
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> ux(0, 239), uy(0, 179), dt(0, 3), pol(0, 1);
  std::vector<Event> ev(n);
  long long t = 18000000;
  for (auto& e : ev) {
    t += dt(rng);
    e.t = double(t) * 1e-6;
    e.x = float(ux(rng));
    e.y = float(uy(rng));
    e.on = pol(rng);
  }
  return ev;
}

struct Inputs {
  std::filesystem::path dir;
  std::size_t n = 4000000;
  std::string txt, a2, a31, a4lz4, a4zstd;
  Inputs() {
    dir = std::filesystem::temp_directory_path() / ("celc_io_bench_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto ev = benchEvents(n);
    txt = (dir / "events.txt").string();
    a2 = (dir / "e.aedat").string();
    a31 = (dir / "e.aedat31").string();
    a4lz4 = (dir / "lz4.aedat4").string();
    a4zstd = (dir / "zstd.aedat4").string();
    writeEventsText(txt, ev);
    writeAedat2(a2, ev, {});
    writeAedat31(a31, ev, {}, "DAVIS240C", 4096);
    writeAedat4(a4lz4, ev, {}, 240, 180, Aedat4Compression::Lz4, 4096, true);
    writeAedat4(a4zstd, ev, {}, 240, 180, Aedat4Compression::Zstd, 4096, true);
  }
  ~Inputs() { std::filesystem::remove_all(dir); }
};

Inputs& inputs() {
  static Inputs in;
  return in;
}

using celc::bench::readAll;

void BM_ReadEventsText(benchmark::State& s) { readAll(s, inputs().txt); }
void BM_ReadAedat2(benchmark::State& s) { readAll(s, inputs().a2); }
void BM_ReadAedat31(benchmark::State& s) { readAll(s, inputs().a31); }
void BM_ReadAedat4Lz4(benchmark::State& s) { readAll(s, inputs().a4lz4); }
void BM_ReadAedat4Zstd(benchmark::State& s) { readAll(s, inputs().a4zstd); }
BENCHMARK(BM_ReadEventsText)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadAedat2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadAedat31)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadAedat4Lz4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadAedat4Zstd)->Unit(benchmark::kMillisecond)->UseRealTime();

long statusKb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::strlen(key));
  return -1;
}

/// Windowed reading of a large events.txt (generated here, `range(0)` M events):
/// reports the peak resident set [MB] during the pass (VmHWM after resetting it
/// through /proc/self/clear_refs) and the file size; memory must not grow with the file.
void BM_WindowedTextPeakMemory(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0)) * 1000000;
  // own file (not inputs()): run alone (--benchmark_filter=Peak) for a clean baseline
  const auto path = (std::filesystem::temp_directory_path() /
                     ("celc_io_bench_big_" + std::to_string(::getpid()) + ".txt")).string();
  if (!std::filesystem::exists(path)) {
    // written in slices so that the generator itself stays small
    std::FILE* f = std::fopen(path.c_str(), "wb");
    std::mt19937 rng(1);
    char line[64];
    std::string buf;
    long long t = 0;
    for (std::size_t i = 0; i < n; ++i) {
      t += rng() % 4;
      const int len = std::snprintf(line, sizeof(line), "%.9f %u %u %u\n", double(t) * 1e-6, unsigned(rng() % 240),
                                    unsigned(rng() % 180), unsigned(rng() & 1));
      buf.append(line, std::size_t(len));
      if (buf.size() > (1 << 22)) std::fwrite(buf.data(), 1, buf.size(), f), buf.clear();
    }
    std::fwrite(buf.data(), 1, buf.size(), f);
    std::fclose(f);
  }
  double peak_mb = 0, base_mb = 0;
  std::size_t windows = 0, peak_buffered = 0;
  for (auto _ : state) {
    { std::ofstream c("/proc/self/clear_refs"); c << "5"; }  // reset VmHWM to the current RSS
    base_mb = double(statusKb("VmRSS:")) / 1024.0;
    auto r = openEventSource(path);
    WindowOptions o;
    o.events_per_window = 30000;
    WindowSource ws(*r, o);
    EventWindow w;
    windows = 0;
    while (ws.next(w)) ++windows;
    peak_buffered = ws.peakBuffered();
    peak_mb = double(statusKb("VmHWM:")) / 1024.0;
  }
  state.counters["file_MB"] = double(std::filesystem::file_size(path)) / 1e6;
  state.counters["peak_RSS_MB"] = peak_mb;
  state.counters["RSS_before_MB"] = base_mb;
  state.counters["windows"] = double(windows);
  state.counters["peak_buffered_events"] = double(peak_buffered);
  std::filesystem::remove(path);
}
BENCHMARK(BM_WindowedTextPeakMemory)->Arg(46)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

CameraModel benchCamera() {
  CameraModel c;
  c.width = 240, c.height = 180;
  c.fx = 199.092366542, c.fy = 198.82882047, c.cx = 132.192071378, c.cy = 110.712660011;
  c.distortion = DistortionModel::RadTan;
  c.coeffs = {-0.368436311798, 0.150947243557, -0.000296130534385, -0.000759431726241, 0.0};
  return c;
}

/// Undistortion of event pixels: table lookup vs CameraModel::bearing (iterative) per event.
void BM_UndistortLut(benchmark::State& state) {
  const CameraModel c = benchCamera();
  const UndistortLut lut(c);
  const auto ev = benchEvents(1 << 16);
  for (auto _ : state) {
    Vec3 sum = Vec3::Zero(), b;
    for (const auto& e : ev)
      if (lut.bearing(int(e.x), int(e.y), b)) sum += b;
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(ev.size()));
}
void BM_UndistortDirect(benchmark::State& state) {
  const CameraModel c = benchCamera();
  const auto ev = benchEvents(1 << 16);
  for (auto _ : state) {
    Vec3 sum = Vec3::Zero();
    for (const auto& e : ev) sum += c.bearing(Vec2(e.x, e.y));
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(ev.size()));
}
void BM_UndistortLutBuild(benchmark::State& state) {
  const CameraModel c = benchCamera();
  for (auto _ : state) benchmark::DoNotOptimize(UndistortLut(c));
}
BENCHMARK(BM_UndistortLut);
BENCHMARK(BM_UndistortDirect);
BENCHMARK(BM_UndistortLutBuild)->Unit(benchmark::kMillisecond);

}  // namespace
