// The seeded event subsets (solver/sampling.hpp): the subset is Floyd's
// sample of its seed, whichever set holds the draws.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "solver/sampling.hpp"

using namespace celc;

namespace {

/// Floyd's algorithm with an ordered set: the reference subset.
std::vector<size_t> floydReference(size_t n, size_t k, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::set<size_t> chosen;
  for (size_t j = n - k; j < n; ++j) {
    const size_t t = std::uniform_int_distribution<size_t>(0, j)(rng);
    if (!chosen.insert(t).second) chosen.insert(j);
  }
  return {chosen.begin(), chosen.end()};
}

}  // namespace

// k at least n / 64 draws into a bitmap, fewer into a hash set: both give
// the reference subset, sorted, k distinct indices below n.
TEST(Sampling, SubsetIsFloydsSampleOfTheSeed) {
  const std::vector<std::pair<size_t, size_t>> cases = {
      {100, 1},      {100, 50},        {100, 99},       {1000, 15},     {1000, 16},
      {64000, 999},  {64000, 1000},    {64000, 1001},   {250000, 40000}, {1000003, 10000},
      {130, 129},    {7, 3}};
  for (const auto& [n, k] : cases)
    for (std::uint64_t seed : {1u, 2u, 77u}) {
      const std::vector<size_t> got = detail::sampleIndices(n, k, seed);
      ASSERT_EQ(got.size(), k) << n << " " << k;
      EXPECT_EQ(got, floydReference(n, k, seed)) << "n " << n << ", k " << k << ", seed " << seed;
      EXPECT_LT(got.back(), n);
    }
  // k = 0 or k >= n: every index.
  EXPECT_EQ(detail::sampleIndices(5, 0, 1), (std::vector<size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(detail::sampleIndices(3, 9, 1), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(detail::sampleIndices(0, 4, 1).empty());
}
