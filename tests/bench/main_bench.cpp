// Google Benchmark entry point; the benchmarks live in one file per module.
// The heap is set up as the `celc` executable sets it (apps/celc/main.cpp),
// so that a benchmark's allocations cost what they cost in a user's run.
#include <benchmark/benchmark.h>

#include "celc/core/memory.hpp"

int main(int argc, char** argv) {
  celc::tuneHeapForLargeBuffers();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
