// The IRLS passes over packed rows (solver/irls_kernel) against a direct,
// row-by-row evaluation of the same sums.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "solver/irls_kernel.hpp"
#include "solver/robust_nullspace.hpp"
#include "solver/sampling.hpp"

using namespace celc;
using detail::ConstraintRow;
using detail::PackedRows;
using detail::PackedSums;

namespace {

// Random rows; with two_rows, N's third row is zero (as in CELC's rows).
// Every 7th row has N = 0 (no normaliser: such a row must get no weight).
std::vector<ConstraintRow> randomRows(size_t n, bool two_rows, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<ConstraintRow> rows(n);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) rows[i].a(k) = g(rng);
    for (int k = 0; k < 9; ++k) rows[i].N(k) = g(rng);
    if (two_rows) rows[i].N.row(2).setZero();
    if (i % 7 == 3) rows[i].N.setZero();
  }
  return rows;
}

enum class Weight { Plain, Huber, Tukey };

// sum w a a^T and sum w N^T N, entries xx yy zz xy xz yz.
PackedSums directSums(const std::vector<ConstraintRow>& rows, const Vec3& v, double thr, Weight kind) {
  Mat3 Sa = Mat3::Zero(), Sn = Mat3::Zero();
  for (const auto& row : rows) {
    const double d = row.a.dot(v), g2 = (row.N * v).squaredNorm();
    double w = 1.0;
    if (kind != Weight::Plain && !(g2 > 0.0)) w = 0.0;
    const double r = g2 > 0.0 ? std::abs(d / std::sqrt(g2)) : 0.0;
    if (kind == Weight::Huber && g2 > 0.0) w = std::min(1.0, thr / r) / g2;
    if (kind == Weight::Tukey && g2 > 0.0) w = r < thr ? std::pow(1.0 - (r / thr) * (r / thr), 2) / g2 : 0.0;
    Sa += w * row.a * row.a.transpose();
    Sn += w * row.N.transpose() * row.N;
  }
  return {Sa(0, 0), Sa(1, 1), Sa(2, 2), Sa(0, 1), Sa(0, 2), Sa(1, 2),
          Sn(0, 0), Sn(1, 1), Sn(2, 2), Sn(0, 1), Sn(0, 2), Sn(1, 2)};
}

void expectSumsNear(const PackedSums& got, const PackedSums& want) {
  double scale = 0.0;
  for (double x : want) scale = std::max(scale, std::abs(x));
  // Sums of a few hundred O(1) products in another order: rounding ~1e-14.
  for (size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(got[k], want[k], 1e-12 * scale) << "entry " << k;
}

}  // namespace

// Row counts around the 8-row blocks (padding), both layouts, thresholds that
// make most rows inliers and most rows outliers (Tukey: beyond the threshold
// a row has no weight).
TEST(IrlsKernel, HuberAndTukeySumsMatchRowByRowEvaluation) {
  std::mt19937_64 rng(3);
  for (const size_t n : {1u, 7u, 8u, 9u, 63u, 300u}) {
    for (const bool two_rows : {true, false}) {
      const auto rows = randomRows(n, two_rows, rng);
      const PackedRows packed(rows);
      EXPECT_EQ(packed.size(), n);
      EXPECT_EQ(packed.normalRows(), two_rows ? 2 : 3);
      expectSumsNear(packed.plainSums(), directSums(rows, Vec3::Zero(), 0.0, Weight::Plain));
      const Vec3 v = Vec3(0.3, -0.8, 0.5).normalized();
      for (const double thr : {0.05, 0.5, 5.0}) {
        expectSumsNear(detail::weightedSums(packed, v, detail::RobustLoss::huber(thr)),
                       directSums(rows, v, thr, Weight::Huber));
        expectSumsNear(detail::weightedSums(packed, v, detail::RobustLoss::tukey(thr)),
                       directSums(rows, v, thr, Weight::Tukey));
      }
    }
  }
}

// Rows appended one by one give the same packing as rows packed at once;
// appending past the capacity is refused.
TEST(IrlsKernel, AppendMatchesPackingAndRespectsCapacity) {
  std::mt19937_64 rng(5);
  const auto rows = randomRows(50, true, rng);
  PackedRows appended(rows.size(), 2);
  for (const auto& row : rows) EXPECT_TRUE(appended.append(row.a, row.N));
  EXPECT_FALSE(appended.append(rows[0].a, rows[0].N));
  appended.seal();
  const PackedRows packed(rows);
  ASSERT_EQ(appended.size(), packed.size());
  const Vec3 v = Vec3(1.0, 2.0, 0.5).normalized();
  const PackedSums a = detail::weightedSums(appended, v, detail::RobustLoss::huber(0.3));
  const PackedSums b = detail::weightedSums(packed, v, detail::RobustLoss::huber(0.3));
  for (size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k], b[k]);
}

// Squared residuals of every row; rows without a normaliser get r_degenerate^2.
TEST(IrlsKernel, SquaredResidualsAndDegenerateRows) {
  std::mt19937_64 rng(7);
  const auto rows = randomRows(40, false, rng);
  const PackedRows packed(rows);
  const Vec3 v = Vec3(-0.2, 0.4, 0.9).normalized();
  std::vector<double> r2;
  packed.squaredResiduals(v, 1e3, r2);
  ASSERT_EQ(r2.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const double g2 = (rows[i].N * v).squaredNorm();
    if (g2 > 0.0) {
      const double want = std::pow(rows[i].a.dot(v), 2) / g2;
      EXPECT_NEAR(r2[i], want, 1e-12 * std::max(1.0, want)) << "row " << i;
    } else {
      EXPECT_EQ(r2[i], 1e6) << "row " << i;
    }
  }
}

// The scale sample is every floor(n / 256)-th row: all rows up to 511, then
// 256 to 511 of them; strided(k) holds rows 0, k, 2k, ...
TEST(IrlsKernel, ScaleSampleAndStridedRows) {
  std::mt19937_64 rng(9);
  const auto rows = randomRows(1000, true, rng);
  const PackedRows packed(rows);
  EXPECT_EQ(packed.scaleSample().size(), 334u);  // stride 3
  const PackedRows few(randomRows(300, true, rng));
  EXPECT_EQ(&few.scaleSample(), &few);  // stride 1: the rows themselves
  const PackedRows sub = packed.strided(10);
  ASSERT_EQ(sub.size(), 100u);
  const Vec3 v = Vec3(0.6, 0.0, 0.8);
  std::vector<double> all, some;
  packed.squaredResiduals(v, 1.0, all);
  sub.squaredResiduals(v, 1.0, some);
  for (size_t k = 0; k < some.size(); ++k) EXPECT_EQ(some[k], all[10 * k]) << "row " << 10 * k;
}

// The IRLS's median of squared residuals with a guess of where it lies
// (detail::kthSmallest) is the value std::nth_element gives, whether the guess
// brackets it, misses it on either side, is empty, NaN, or a single value;
// with ties, below and above the size where the guess is used.
TEST(IrlsKernel, KthSmallestEqualsNthElementWhateverTheGuess) {
  std::mt19937_64 rng(11);
  std::chi_squared_distribution<double> chi2(1.0);
  std::vector<double> band;
  int checked = 0;
  for (size_t n : {1u, 10u, 31u, 32u, 100u, 1000u}) {
    for (int trial = 0; trial < 4; ++trial) {
      std::vector<double> x(n);
      // Trials 2 and 3: values rounded to 0.1, so many are tied.
      for (double& v : x) v = trial < 2 ? chi2(rng) : std::round(10.0 * chi2(rng)) / 10.0;
      for (size_t k : {size_t{0}, n / 2, n - 1}) {
        std::vector<double> ref = x;
        std::nth_element(ref.begin(), ref.begin() + static_cast<long>(k), ref.end());
        const double want = ref[k];
        const double guesses[][2] = {{want / 1.5, want * 1.5}, {want, want}, {want * 2 + 1, want * 3 + 2},
                                     {want / 3 - 1, want / 2 - 0.5}, {2.0, 1.0}, {NAN, NAN}};
        for (const auto& guess : guesses) {
          std::vector<double> y = x;
          EXPECT_EQ(detail::kthSmallest(y, k, guess[0], guess[1], band), want)
              << "n " << n << " k " << k << " guess [" << guess[0] << ", " << guess[1] << "]";
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 6 * 4 * 3 * 6);
}

// The grid's best starts (gridStarts: medians selected only for directions
// that can still rank among the best) are those of ranking every direction
// by its median squared residual on the same strided rows: rows with noise
// around one direction (found up to its sign: the lattice is a hemisphere),
// pure noise, and rows of which every 7th has N = 0.
TEST(GridStarts, BestDirectionsOfTheFullRanking) {
  std::mt19937_64 rng(99);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<ConstraintRow> rows = randomRows(1000 + 37 * trial, true, rng);
    const Vec3 truth = Vec3(g(rng), g(rng), std::abs(g(rng)) + 0.1).normalized();
    if (trial % 2 == 0)  // a^T truth about 0: the rows hold a solution
      for (auto& r : rows) r.a -= truth * (r.a.dot(truth) + 0.01 * g(rng));
    const PackedRows packed(rows);
    for (const auto& [n, keep, scored] : {std::tuple{256, 4, 200}, std::tuple{64, 1, 1000}, std::tuple{100, 8, 50}}) {
      const PackedRows sub = packed.strided(packed.size() / static_cast<size_t>(scored));
      std::vector<std::pair<double, int>> all;
      std::vector<double> r2;
      const std::vector<Vec3>& dirs = detail::hemisphereDirections(n);
      for (int i = 0; i < n; ++i) {
        sub.squaredResiduals(dirs[i], 1e300, r2);
        std::nth_element(r2.begin(), r2.begin() + static_cast<long>(r2.size() / 2), r2.end());
        all.emplace_back(r2[r2.size() / 2], i);
      }
      std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      const std::vector<Vec3> best = detail::gridStarts(packed, n, keep, scored);
      ASSERT_EQ(best.size(), static_cast<size_t>(keep)) << "trial " << trial;
      for (int k = 0; k < keep; ++k)
        EXPECT_EQ(best[k], dirs[all[k].second]) << "trial " << trial << ", n " << n << ", rank " << k;
      if (trial % 2 == 0) {
        EXPECT_GT(std::abs(best[0].dot(truth)), 0.95) << "trial " << trial << ", n " << n;
      }
    }
  }
}
