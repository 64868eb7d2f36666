// Throughput (events/s, one core) of the ROS bag and HDF5 readers, and the
// memory of windowed reading from a bag. The inputs are written once per
// process by celc_make_fixtures --bench (tests/fixtures/make_fixtures.cpp) into
// the temp directory and removed at exit.
// Targets (docs/formats.md): bag with lz4 chunks >= 10 M/s, HDF5 uncompressed >= 20 M/s.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "celc/io/event_reader.hpp"
#include "celc/io/window_source.hpp"
#include "read_all.hpp"

using celc::bench::readAll;

namespace {

using namespace celc;

struct ContainerInputs {
  std::filesystem::path dir;
  bool ok = false;
  ContainerInputs() {
    dir = std::filesystem::temp_directory_path() / ("celc_io_container_bench_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string cmd = "'" CELC_MAKE_FIXTURES "' --bench 4000000 '" + dir.string() + "'";
    ok = std::system(cmd.c_str()) == 0;
  }
  ~ContainerInputs() { std::filesystem::remove_all(dir); }
  std::string file(const char* name) const { return (dir / name).string(); }
};

ContainerInputs& containerInputs() {
  static ContainerInputs in;
  return in;
}

void readContainer(benchmark::State& state, const char* name) {
  if (!containerInputs().ok) {
    state.SkipWithError("celc_make_fixtures --bench failed");
    return;
  }
  readAll(state, containerInputs().file(name));
}

void BM_ReadRosBagLz4(benchmark::State& s) { readContainer(s, "bench_lz4.bag"); }
void BM_ReadRosBagUncompressed(benchmark::State& s) { readContainer(s, "bench_none.bag"); }
void BM_ReadHdf5Dsec(benchmark::State& s) { readContainer(s, "bench_dsec.h5"); }
void BM_ReadHdf5Mvsec(benchmark::State& s) { readContainer(s, "bench_mvsec.h5"); }
BENCHMARK(BM_ReadRosBagLz4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadRosBagUncompressed)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadHdf5Dsec)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadHdf5Mvsec)->Unit(benchmark::kMillisecond)->UseRealTime();

long statusKbOf(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::strlen(key));
  return -1;
}

/// Windowed reading (30000 events per window) of the lz4 bag and the DSEC file:
/// the peak resident set above the start [MB] against the file size.
void windowedPeak(benchmark::State& state, const char* name) {
  if (!containerInputs().ok) {
    state.SkipWithError("celc_make_fixtures --bench failed");
    return;
  }
  const std::string path = containerInputs().file(name);
  double grow_mb = 0;
  std::size_t windows = 0;
  for (auto _ : state) {
    { std::ofstream c("/proc/self/clear_refs"); c << "5"; }  // reset VmHWM to the current RSS
    const double base_mb = double(statusKbOf("VmRSS:")) / 1024.0;
    auto r = openEventSource(path);
    WindowOptions o;
    o.events_per_window = 30000;
    WindowSource ws(*r, o);
    EventWindow w;
    windows = 0;
    while (ws.next(w)) ++windows;
    grow_mb = double(statusKbOf("VmHWM:")) / 1024.0 - base_mb;
  }
  state.counters["file_MB"] = double(std::filesystem::file_size(path)) / 1e6;
  state.counters["peak_RSS_growth_MB"] = grow_mb;
  state.counters["windows"] = double(windows);
}
void BM_WindowedRosBagPeakMemory(benchmark::State& s) { windowedPeak(s, "bench_lz4.bag"); }
void BM_WindowedHdf5PeakMemory(benchmark::State& s) { windowedPeak(s, "bench_dsec.h5"); }
BENCHMARK(BM_WindowedRosBagPeakMemory)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WindowedHdf5PeakMemory)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
