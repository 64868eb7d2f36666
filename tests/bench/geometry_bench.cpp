#include <benchmark/benchmark.h>

#include "celc/geometry/so3.hpp"

static void BM_So3Exp(benchmark::State& state) {
  celc::Vec3 phi(0.1, -0.2, 0.3);
  for (auto _ : state) {
    phi.x() += 1e-9;
    benchmark::DoNotOptimize(celc::so3::exp(phi));
  }
}
BENCHMARK(BM_So3Exp);
