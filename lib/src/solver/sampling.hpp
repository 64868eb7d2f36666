#pragma once
// Internal: seeded event subsets and robust medians.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace celc::detail {

/// Seeded random subset of k of the indices 0..n-1, sorted (all when k == 0 or k >= n).
std::vector<size_t> sampleIndices(size_t n, size_t k, std::uint64_t seed);

/// Rows per cluster out of a budget (0 = every event). Balanced: water-filling,
/// every cluster the same share unless it has fewer events; else proportional
/// to the sizes (rounded down).
std::vector<size_t> rowQuota(const std::vector<size_t>& sizes, size_t budget, bool balanced);

/// Median of |x| (upper median for an even count; x is overwritten and reordered). 0 when empty.
double medianAbs(std::vector<double>& x);

}  // namespace celc::detail
