// Google Benchmark entry point; the benchmarks live in one file per module.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
