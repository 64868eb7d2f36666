// Clustering speed and memory on a labelled synthetic window: 1,000,000 events
// from 15 moving lines with 10% noise (DAVIS240C geometry), 2 threads.
//
// Counters:
//   events_per_s     events clustered per second (wall clock, the whole clusterEvents call)
//   peak_B_per_event peak heap bytes allocated by clusterEvents above what was
//                    allocated before the call, divided by the window's events. Measured
//                    with a counting global operator new/delete in this binary (every
//                    std::vector/new of celc; PCL's Eigen-aligned buffers that go through
//                    malloc directly are not counted, see maxrss_MB for those).
//   maxrss_MB        the process's peak resident set (getrusage), a whole-process upper bound.
//   recovered        share of true lines recovered (>= 80% of its events in one cluster, purity >= 0.9)
//
// The PCL reference takes minutes on 1M events on two cores, so it is measured on a
// 100,000-event window of the same scene; compare events_per_s and peak_B_per_event.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <atomic>
#include <cstdlib>
#include <map>
#include <new>

#include "celc/cluster/cluster.hpp"
#include "celc/cluster/line_split.hpp"
#include "celc/cluster/motion_reassign.hpp"
#include "celc/cluster/synthetic.hpp"

namespace {
std::atomic<long long> g_current{0}, g_peak{0};

void* countedAlloc(std::size_t size) {
  void* p = std::malloc(size + 16);
  if (!p) throw std::bad_alloc();
  *static_cast<std::size_t*>(p) = size;
  const long long now = g_current.fetch_add(static_cast<long long>(size)) + static_cast<long long>(size);
  long long peak = g_peak.load();
  while (now > peak && !g_peak.compare_exchange_weak(peak, now)) {
  }
  return static_cast<char*>(p) + 16;
}
void countedFree(void* p) {
  if (!p) return;
  char* base = static_cast<char*>(p) - 16;
  g_current.fetch_sub(static_cast<long long>(*reinterpret_cast<std::size_t*>(base)));
  std::free(base);
}
}  // namespace

void* operator new(std::size_t size) { return countedAlloc(size); }
void* operator new[](std::size_t size) { return countedAlloc(size); }
void operator delete(void* p) noexcept { countedFree(p); }
void operator delete[](void* p) noexcept { countedFree(p); }
void operator delete(void* p, std::size_t) noexcept { countedFree(p); }
void operator delete[](void* p, std::size_t) noexcept { countedFree(p); }

namespace {

const celc::LabelledWindow& window(int n_events) {
  static std::map<int, celc::LabelledWindow> cache;
  auto it = cache.find(n_events);
  if (it == cache.end()) {
    celc::LabelledWindowOptions o;
    o.n_events = n_events;
    o.n_lines = 15;
    o.noise_fraction = 0.1;
    o.duration_s = 0.5;
    o.speed_m_per_s = 0.6;
    o.omega_rad_per_s = 0.15;
    o.seed = 7;
    it = cache.emplace(n_events, celc::generateLabelledWindow(o)).first;
  }
  return it->second;
}

double recoveredShare(const celc::LabelledWindow& w, const celc::ClusterResult& r) {
  std::map<std::pair<int, int>, int> joint;
  std::vector<int> line_size(w.n_lines(), 0), cluster_size(r.clusters.size(), 0);
  for (size_t i = 0; i < w.events.size(); ++i) {
    if (r.labels[i] >= 0) ++cluster_size[r.labels[i]];
    if (w.labels[i] >= 0) ++line_size[w.labels[i]];
    if (w.labels[i] >= 0 && r.labels[i] >= 0) ++joint[{w.labels[i], r.labels[i]}];
  }
  int rec = 0;
  for (int l = 0; l < w.n_lines(); ++l) {
    for (const auto& [key, n] : joint) {
      if (key.first == l && n >= 0.8 * line_size[l] && n >= 0.9 * cluster_size[key.second]) {
        ++rec;
        break;
      }
    }
  }
  return w.n_lines() ? static_cast<double>(rec) / w.n_lines() : 0.0;
}

/// Arguments: the window's events, and cluster.threads (`celc run --threads 2`
/// clusters two windows at once, each on one thread; a window alone on two).
/// `line_split`: each cluster cut to its moving lines; `redraw`: then the
/// clusters redrawn under the window's true velocity (motion_reassign.hpp),
/// the stage `celc run` adds after a first solve.
void runCluster(benchmark::State& state, celc::ClusterMethod method, bool line_split = false, bool redraw = false) {
  const celc::LabelledWindow& w = window(static_cast<int>(state.range(0)));
  celc::ClusterOptions opt;
  opt.method = method;
  opt.threads = state.range(1) > 0 ? static_cast<int>(state.range(1)) : 2;
  celc::ClusterResult r;
  long long peak_extra = 0;
  double cpu_ms = 0.0;
  auto cpuNow = [] {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return 1e3 * (u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-3 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  };
  for (auto _ : state) {
    const double cpu0 = cpuNow();
    const long long before = g_current.load();
    g_peak.store(before);
    r = celc::clusterEvents(w.events, opt);
    if (line_split) {
      const celc::MotionModel motion = celc::MotionModel::constantTwist(w.omega, 0.0);
      celc::splitByMovingLines(w.events, r, [&](const celc::Vec2& p) { return w.camera.bearing(p); },
                               w.camera.focal(), &motion, opt);
      if (redraw)
        celc::reassignToMotionLines(w.events, r.labels, [&](const celc::Vec2& p) { return w.camera.bearing(p); },
                                    w.camera.focal(), motion, w.v.normalized(), opt);
    }
    peak_extra = std::max(peak_extra, g_peak.load() - before);
    benchmark::DoNotOptimize(r.labels.data());
    cpu_ms += cpuNow() - cpu0;
  }
  // CPU time of all threads per window: on a shared machine, wall time / 2 cores
  // cannot be better than cpu_ms / 2.
  state.counters["cpu_ms_all_threads"] = cpu_ms / static_cast<double>(state.iterations());
  const double n = static_cast<double>(w.events.size());
  state.counters["events_per_s"] =
      benchmark::Counter(n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["peak_B_per_event"] = static_cast<double>(peak_extra) / n;
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["maxrss_MB"] = static_cast<double>(ru.ru_maxrss) / 1024.0;
  state.counters["clusters"] = static_cast<double>(r.clusters.size());
  state.counters["recovered"] = recoveredShare(w, r);
  state.counters["c_px_per_s"] = r.c_px_per_s;
  state.counters["ms_index_c"] = r.ms_time_scale;
  state.counters["ms_normals"] = r.ms_normals;
  state.counters["ms_grow"] = r.ms_grow;
  state.counters["ms_post"] = r.ms_post;
}

void BM_ClusterGrid(benchmark::State& state) { runCluster(state, celc::ClusterMethod::Grid); }
void BM_ClusterPcl(benchmark::State& state) { runCluster(state, celc::ClusterMethod::Pcl); }
/// The grid grower, then each cluster cut to its moving lines (line_split.hpp), as `celc run` clusters.
void BM_ClusterGridLineSplit(benchmark::State& state) { runCluster(state, celc::ClusterMethod::Grid, true); }
/// ... and redrawn under the motion (cluster.motion_reassign_px); its cost is
/// the difference from BM_ClusterGridLineSplit.
void BM_ClusterGridRedraw(benchmark::State& state) { runCluster(state, celc::ClusterMethod::Grid, true, true); }

}  // namespace

BENCHMARK(BM_ClusterGrid)->Args({1000000, 2})->Args({1000000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_ClusterGridLineSplit)->Args({1000000, 2})->Args({1000000, 1})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_ClusterGridRedraw)->Args({1000000, 2})->Args({1000000, 1})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_ClusterPcl)->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
