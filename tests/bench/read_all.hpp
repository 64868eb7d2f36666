#pragma once
// Shared by the reader benchmarks: every event of a file, read through
// openEventSource in batches of 65,536; items/s = events/s, counter MB = file size.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc::bench {

inline void readAll(benchmark::State& state, const std::string& path) {
  std::vector<Event> batch;
  std::size_t total = 0;
  for (auto _ : state) {
    auto r = openEventSource(path);
    std::size_t n = 0;
    while (r->next(batch, 1 << 16)) n += batch.size();
    benchmark::DoNotOptimize(n);
    total += n;
  }
  state.SetItemsProcessed(std::int64_t(total));
  state.counters["MB"] = double(std::filesystem::file_size(path)) / 1e6;
}

}  // namespace celc::bench
