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

/// The k-th smallest of x (0-based, k < x.size(); x is reordered), the value
/// std::nth_element puts at k. [lo, hi] is a guess of where it lies: when it
/// holds (and x holds a few dozen values), only the values inside it are
/// selected among (after one pass without branches that moves them into
/// `band`), else all of x are.
double kthSmallest(std::vector<double>& x, size_t k, double lo, double hi, std::vector<double>& band);

/// Median of |x| (upper median for an even count; x is overwritten and reordered). 0 when empty.
double medianAbs(std::vector<double>& x);

/// The spread of residuals d [px]: their robust scale 1.4826 median |d|, and
/// the share of them with |d| beyond 3 times it (Gaussian noise: 0.27%; a
/// non-finite d counts as beyond).
struct ResidualSpread {
  double scale = 0.0;
  double tail_share = 0.0;
  /// The scale c [px] of a last refinement under the Cauchy loss: factor
  /// times the robust scale when more than min_tail of the residuals lie
  /// beyond 3 scales; 0 (no such refinement) otherwise.
  double cauchyScale(double factor, double min_tail) const;
};
ResidualSpread residualSpread(std::vector<double> d);

}  // namespace celc::detail
