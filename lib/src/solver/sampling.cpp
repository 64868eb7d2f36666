// Seeded event subsets and robust medians.
#include "sampling.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_set>

namespace celc::detail {

std::vector<size_t> sampleIndices(size_t n, size_t k, std::uint64_t seed) {
  std::vector<size_t> idx;
  if (k == 0 || k >= n) {
    idx.resize(n);
    for (size_t i = 0; i < n; ++i) idx[i] = i;
    return idx;
  }
  // Floyd's algorithm: k draws; the chosen set is a bitmap of n bits when
  // k is a fair share of n (read out in order, no sort), else a hash set
  // (no O(n) buffer). Both hold the same draws, so the subset is the same.
  std::mt19937_64 rng(seed);
  idx.reserve(k);
  if (k >= n / 64) {
    std::vector<std::uint64_t> bits((n + 63) / 64, 0);
    for (size_t j = n - k; j < n; ++j) {
      const size_t t = std::uniform_int_distribution<size_t>(0, j)(rng);
      const std::uint64_t bit = std::uint64_t{1} << (t % 64);
      if (bits[t / 64] & bit)
        bits[j / 64] |= std::uint64_t{1} << (j % 64);
      else
        bits[t / 64] |= bit;
    }
    for (size_t w = 0; w < bits.size(); ++w)
      for (std::uint64_t b = bits[w]; b != 0; b &= b - 1)
        idx.push_back(64 * w + static_cast<size_t>(__builtin_ctzll(b)));
    return idx;
  }
  std::unordered_set<size_t> chosen;
  chosen.reserve(2 * k);
  for (size_t j = n - k; j < n; ++j) {
    const size_t t = std::uniform_int_distribution<size_t>(0, j)(rng);
    if (!chosen.insert(t).second) chosen.insert(j);
  }
  idx.assign(chosen.begin(), chosen.end());
  std::sort(idx.begin(), idx.end());
  return idx;
}

std::vector<size_t> rowQuota(const std::vector<size_t>& sizes, size_t budget, bool balanced) {
  size_t total = 0;
  for (size_t s : sizes) total += s;
  if (budget == 0 || total <= budget) return sizes;
  std::vector<size_t> q(sizes.size());
  if (!balanced) {
    for (size_t i = 0; i < sizes.size(); ++i) q[i] = sizes[i] * budget / total;
    return q;
  }
  // Water-filling from the smallest cluster up: a long edge must not outvote the others.
  std::vector<size_t> order(sizes.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return sizes[a] < sizes[b]; });
  size_t remaining = budget;
  for (size_t j = 0; j < order.size(); ++j) {
    const size_t share = remaining / (order.size() - j);
    q[order[j]] = std::min(sizes[order[j]], share);
    remaining -= q[order[j]];
  }
  return q;
}

namespace {
// From this many values the guess is tried (it was 256): at 100 values
// (celc_ml's linear start at 5 x 20 events) the selection's share of
// BM_CelcMlPeers/20 went 4.3% -> 2.9% (perf).
constexpr size_t kBandSelectionMin = 32;
}  // namespace

double kthSmallest(std::vector<double>& x, size_t k, double lo, double hi, std::vector<double>& band) {
  // Below a few dozen values the full selection is as quick.
  if (x.size() >= kBandSelectionMin && lo <= hi) {
    band.resize(x.size());
    size_t below = 0, inside = 0;
    for (double v : x) {
      below += v < lo;
      band[inside] = v;
      inside += (v >= lo) & (v <= hi);
    }
    // The k-th smallest lies in [lo, hi] exactly when below <= k < below + inside.
    if (below <= k && k < below + inside) {
      const auto kth = band.begin() + static_cast<long>(k - below);
      std::nth_element(band.begin(), kth, band.begin() + static_cast<long>(inside));
      return *kth;
    }
  }
  const auto kth = x.begin() + static_cast<long>(k);
  std::nth_element(x.begin(), kth, x.end());
  return *kth;
}

double medianAbs(std::vector<double>& x) {
  if (x.empty()) return 0.0;
  for (double& v : x) v = std::abs(v);
  auto mid = x.begin() + static_cast<long>(x.size() / 2);
  std::nth_element(x.begin(), mid, x.end());
  return *mid;
}

ResidualSpread residualSpread(std::vector<double> d) {
  ResidualSpread out;
  if (d.empty()) return out;
  out.scale = 1.4826 * medianAbs(d);  // d now holds |d|, reordered
  size_t beyond = 0;
  for (double x : d) beyond += !(x <= 3.0 * out.scale);
  out.tail_share = static_cast<double>(beyond) / static_cast<double>(d.size());
  return out;
}

double ResidualSpread::cauchyScale(double factor, double min_tail) const {
  const double c = factor * scale;
  return c > 0.0 && std::isfinite(c) && tail_share > min_tail ? c : 0.0;
}

}  // namespace celc::detail
