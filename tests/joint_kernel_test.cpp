// celc_ml's per-event passes over packed columns (solver/joint_kernel)
// against the same sums formed event by event with eventDistance.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <random>

#include "solver/joint_kernel.hpp"
#include "solver/refine_costs.hpp"
#include "solver/sphere_tangent.hpp"

using namespace celc;
using detail::JointBlockSums;
using detail::JointColumns;
using detail::RobustLoss;

namespace {

Vec3 randomVec(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vec3(g(rng), g(rng), g(rng)) * scale;
}

// Random event terms near a CELC geometry: a unit bearing, R^T's first two
// rows of a random rotation, De, Ds of the size of a displacement over
// 0.5 s. Events 125 and 130 see no image direction (R^T's rows zero).
std::vector<EventTerm> randomTerms(size_t n, std::mt19937_64& rng) {
  std::vector<EventTerm> terms(n);
  for (size_t k = 0; k < n; ++k) {
    const Mat3 R = Eigen::AngleAxisd(0.3, randomVec(rng, 1.0).normalized()).toRotationMatrix();
    terms[k].fp = (Vec3(0.0, 0.0, 1.0) + randomVec(rng, 0.3)).normalized();
    terms[k].Rt01 = R.transpose().topRows<2>();
    if (k == 125 || k == 130) terms[k].Rt01.setZero();
    terms[k].De = Mat3::Identity() * 0.25 + Mat3::Random() * 0.02;
    terms[k].Ds = Mat3::Identity() * -0.25 + Mat3::Random() * 0.02;
  }
  return terms;
}

// The sums event by event, as JointProblem::refine formed them before the kernel.
JointBlockSums directSums(const std::vector<EventTerm>& terms, size_t begin, size_t end, size_t step,
                          const Vec3& v, const Vec3& m1, const Vec3& m3, const detail::Mat32& Bv,
                          const detail::Mat32& B1, const detail::Mat32& B3, double focal, RobustLoss::Type loss,
                          double scale) {
  Eigen::Matrix2d V = Eigen::Matrix2d::Zero();
  Eigen::Vector2d bv = Eigen::Vector2d::Zero();
  Eigen::Matrix4d U = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 2, 4> W = Eigen::Matrix<double, 2, 4>::Zero();
  Eigen::Vector4d bc = Eigen::Vector4d::Zero();
  for (size_t k = begin; k < end; k += step) {
    Vec3 gv, g1, g3;
    const double d = eventDistance(terms[k], v, m1, m3, focal, &gv, &g1, &g3);
    if (!std::isfinite(d)) continue;
    double slope, r;
    if (loss == RobustLoss::Type::Huber) {
      r = detail::sqrtHuber(d, scale, &slope);
    } else if (loss == RobustLoss::Type::Cauchy) {
      slope = 1.0 / std::sqrt(1.0 + (d / scale) * (d / scale));
      r = slope * d;
    } else {  // Tukey: sqrt(w) = 1 - (d / c)^2 within c, 0 beyond
      slope = std::abs(d) < scale ? 1.0 - (d / scale) * (d / scale) : 0.0;
      r = slope * d;
    }
    const Eigen::Vector2d jv = slope * (Bv.transpose() * gv);
    Eigen::Vector4d jc;
    jc << slope * (B1.transpose() * g1), slope * (B3.transpose() * g3);
    V += jv * jv.transpose(), bv += jv * r;
    U += jc * jc.transpose(), W += jv * jc.transpose(), bc += jc * r;
  }
  JointBlockSums out;
  out.V[0] = V(0, 0), out.V[1] = V(0, 1), out.V[2] = V(1, 1);
  out.bv[0] = bv(0), out.bv[1] = bv(1);
  for (int i = 0, k = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) out.U[k++] = U(i, j);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 4; ++j) out.W[4 * i + j] = W(i, j);
  for (int i = 0; i < 4; ++i) out.bc[i] = bc(i);
  return out;
}

void expectSumsNear(const JointBlockSums& got, const JointBlockSums& want) {
  const double* g = got.V;
  const double* w = want.V;
  double scale = 0.0;
  for (int k = 0; k < 27; ++k) scale = std::max(scale, std::abs(w[k]));
  // Sums of a few hundred products in another order: rounding ~1e-14 relative.
  for (int k = 0; k < 27; ++k) EXPECT_NEAR(g[k], w[k], 1e-11 * scale) << "sum " << k;
}

}  // namespace

// Three clusters of 61, 0 and 140 events, every event and every 3rd, both
// losses, thresholds that leave most events inside and most outside Huber's
// quadratic part; events without an image direction add nothing.
TEST(JointKernel, BlockSumsAndCostMatchEventByEvent) {
  std::mt19937_64 rng(3);
  const std::vector<EventTerm> terms = randomTerms(201, rng);
  const std::vector<size_t> begin = {0, 61, 61, 201};
  const double focal = 320.0;
  int checked = 0, tukey_inside = 0, tukey_beyond = 0;
  for (size_t step : {size_t{1}, size_t{3}}) {
    JointColumns columns;
    std::vector<size_t> column_begin;
    columns.assign(terms, begin, step, column_begin);
    ASSERT_EQ(column_begin.size(), begin.size());
    for (int trial = 0; trial < 3; ++trial) {
      const Vec3 v = randomVec(rng, 1.0).normalized();
      const Vec3 m1 = randomVec(rng, 1.0).normalized(), m3 = randomVec(rng, 1.0).normalized();
      const detail::Mat32 Bv = detail::tangentBasis(v), B1 = detail::tangentBasis(m1),
                          B3 = detail::tangentBasis(m3);
      for (size_t c = 0; c + 1 < begin.size(); ++c) {
        for (RobustLoss::Type loss : {RobustLoss::Type::Huber, RobustLoss::Type::Cauchy, RobustLoss::Type::Tukey}) {
          for (double scale : {0.5, 50.0}) {
            const JointBlockSums got =
                detail::jointBlockSums(columns, column_begin[c], column_begin[c + 1], v, m1, m3, Bv.data(),
                                       B1.data(), B3.data(), focal, RobustLoss{loss, scale});
            expectSumsNear(got, directSums(terms, begin[c], begin[c + 1], step, v, m1, m3, Bv, B1, B3, focal,
                                           loss, scale));
            ++checked;
            if (loss == RobustLoss::Type::Tukey)  // both sides of Tukey's cut are exercised
              for (size_t k = begin[c]; k < begin[c + 1]; k += step) {
                const double d = eventDistance(terms[k], v, m1, m3, focal, nullptr, nullptr, nullptr);
                if (std::isfinite(d)) ++(std::abs(d) < scale ? tukey_inside : tukey_beyond);
              }
          }
        }
        // The Huber cost: +inf with an event that has no image direction
        // (the third cluster: 125 and 130; every 3rd event: 130).
        double want = 0.0;
        bool finite = true;
        for (size_t k = begin[c]; k < begin[c + 1]; k += step) {
          const double d = eventDistance(terms[k], v, m1, m3, focal, nullptr, nullptr, nullptr);
          double slope;
          const double r = detail::sqrtHuber(d, 2.0, &slope);
          finite = finite && std::isfinite(d);
          want += r * r;
        }
        const double got =
            detail::jointHuberCost(columns, column_begin[c], column_begin[c + 1], v, m1, m3, focal, 2.0);
        EXPECT_EQ(finite, c != 2);
        if (!finite) {
          EXPECT_TRUE(std::isinf(got)) << "cluster " << c;
        } else {
          EXPECT_NEAR(got, want, 1e-11 * std::max(1.0, want)) << "cluster " << c;
        }
      }
    }
  }
  EXPECT_EQ(checked, 2 * 3 * 3 * 3 * 2);
  EXPECT_GT(tukey_inside, 50);
  EXPECT_GT(tukey_beyond, 50);
}

// A problem's columns are written row by row (startRows, appendRow, room for
// more rows than written) and strided from those rows (assignStrided): every
// sum and distance equals the one from columns packed at that step from the
// array of terms (assign), bit for bit, and term() gives each term back.
TEST(JointKernel, RowsWrittenOnceGiveTheSameColumnsAsPacking) {
  std::mt19937_64 rng(5);
  const std::vector<EventTerm> terms = randomTerms(201, rng);
  const std::vector<size_t> begin = {0, 61, 61, 201};
  const double focal = 320.0;
  for (bool acceleration : {false, true}) {
    std::vector<Eigen::Vector2d> dq;
    for (size_t k = 0; k < terms.size(); ++k) dq.emplace_back(0.01 * static_cast<double>(k), -0.02);
    JointColumns full(JointColumns::Spare::Full);
    full.startRows(2, acceleration);
    full.appendRow(terms[0], dq[0]);
    full.appendRow(terms[1], dq[1]);
    EXPECT_THROW(full.appendRow(terms[2], dq[2]), std::logic_error);  // no room beyond max_rows
    JointColumns rows(JointColumns::Spare::Full);
    rows.startRows(terms.size() + 17, acceleration);
    for (size_t k = 0; k < terms.size(); ++k) rows.appendRow(terms[k], dq[k]);
    ASSERT_EQ(rows.size(), terms.size());
    EXPECT_GE(rows.stride(), rows.size() + JointColumns::kPadding);
    for (size_t k : {size_t{0}, size_t{100}, size_t{200}}) {
      const EventTerm e = rows.term(k);
      EXPECT_EQ(e.fp, terms[k].fp);
      EXPECT_EQ(e.Rt01, terms[k].Rt01);
      EXPECT_EQ(e.De, terms[k].De);
      EXPECT_EQ(e.Ds, terms[k].Ds);
    }
    for (size_t step : {size_t{1}, size_t{3}, size_t{10}}) {
      JointColumns packed, strided;
      std::vector<size_t> packed_begin, strided_begin;
      packed.assign(terms, begin, step, packed_begin, acceleration ? &dq : nullptr);
      strided.assignStrided(rows, begin, step, strided_begin);
      ASSERT_EQ(strided_begin, packed_begin);
      ASSERT_EQ(strided.size(), packed.size());
      EXPECT_EQ(strided.hasAcceleration(), acceleration);
      const JointColumns& mine = step == 1 ? rows : strided;
      const std::vector<size_t>& mine_begin = step == 1 ? begin : strided_begin;
      const Vec3 v = randomVec(rng, 1.0).normalized();
      const Vec3 m1 = randomVec(rng, 1.0).normalized(), m3 = randomVec(rng, 1.0).normalized();
      const Vec3 a = randomVec(rng, 0.5);
      const detail::Mat32 Bv = detail::tangentBasis(v), B1 = detail::tangentBasis(m1), B3 = detail::tangentBasis(m3);
      for (size_t c = 0; c + 1 < begin.size(); ++c) {
        const size_t n = packed_begin[c + 1] - packed_begin[c];
        std::vector<double> got(n + 1, -1.0), want(n + 1, -1.0);
        detail::jointDistances(mine, mine_begin[c], mine_begin[c + 1], v, m1, m3, focal, got.data(),
                               acceleration ? &a : nullptr);
        detail::jointDistances(packed, packed_begin[c], packed_begin[c + 1], v, m1, m3, focal, want.data(),
                               acceleration ? &a : nullptr);
        for (size_t i = 0; i < n; ++i) {
          if (std::isfinite(want[i]) || std::isfinite(got[i])) {
            EXPECT_EQ(got[i], want[i]) << "event " << i;
          }
        }
        if (acceleration) continue;
        const JointBlockSums s1 = detail::jointBlockSums(mine, mine_begin[c], mine_begin[c + 1], v, m1, m3,
                                                         Bv.data(), B1.data(), B3.data(), focal,
                                                         RobustLoss{RobustLoss::Type::Huber, 2.0});
        const JointBlockSums s2 = detail::jointBlockSums(packed, packed_begin[c], packed_begin[c + 1], v, m1, m3,
                                                         Bv.data(), B1.data(), B3.data(), focal,
                                                         RobustLoss{RobustLoss::Type::Huber, 2.0});
        static_assert(sizeof(JointBlockSums) == 27 * sizeof(double), "27 sums, no padding");
        std::array<double, 27> a1, a2;
        std::memcpy(a1.data(), &s1, sizeof s1);
        std::memcpy(a2.data(), &s2, sizeof s2);
        EXPECT_EQ(a1, a2);
      }
    }
  }
}
