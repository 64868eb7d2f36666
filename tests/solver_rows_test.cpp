// The linear solvers' building blocks: the closed-form 3x3 generalised
// eigensolver against Eigen's iterative one, and the robust nullspace.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "celc/geometry/line_motion.hpp"
#include "celc/sim/line_scene.hpp"
#include "celc/solver/solver.hpp"
#include "solver/constraint_rows.hpp"
#include "solver/irls_kernel.hpp"
#include "solver/robust_nullspace.hpp"
#include "solver/sign_test.hpp"
#include "solver/window_checks.hpp"

using namespace celc;

namespace {

Mat3 randomMatrix(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Mat3 M;
  for (int i = 0; i < 9; ++i) M(i) = n(rng);
  return M;
}

// Random SPD matrix with eigenvalues 10^[-e, 0] in a random basis.
Mat3 randomSpd(std::mt19937_64& rng, double max_exponent) {
  std::uniform_real_distribution<double> u(-max_exponent, 0.0);
  const Mat3 Q = Eigen::HouseholderQR<Mat3>(randomMatrix(rng)).householderQ();
  const Vec3 d(std::pow(10.0, u(rng)), std::pow(10.0, u(rng)), std::pow(10.0, u(rng)));
  return Q * d.asDiagonal() * Q.transpose();
}

}  // namespace

// Random SPD pairs, well and badly conditioned (A like an IRLS system near its
// nullspace: one eigenvalue 1e-8 of the others): same eigenvalues and the
// same smallest eigenvector (up to sign) as GeneralizedSelfAdjointEigenSolver.
TEST(GeneralizedEigen3, MatchesEigenOnRandomSpd) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 2000; ++trial) {
    const Mat3 A = randomSpd(rng, trial % 2 ? 8.0 : 2.0);
    const Mat3 B = randomSpd(rng, 2.0);
    Vec3 values;
    Mat3 vectors;
    ASSERT_TRUE(detail::generalizedEigen3(A, B, values, vectors));
    const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> ref(A, B);
    ASSERT_EQ(ref.info(), Eigen::Success);
    const double scale = ref.eigenvalues().cwiseAbs().maxCoeff();
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(values(i), ref.eigenvalues()(i), 1e-12 * scale);
    EXPECT_LE(values(0), values(1));
    EXPECT_LE(values(1), values(2));
    // B-orthonormal, and A x = lambda B x.
    EXPECT_LT((vectors.transpose() * B * vectors - Mat3::Identity()).norm(), 1e-9);
    for (int i = 0; i < 3; ++i)
      EXPECT_LT((A * vectors.col(i) - values(i) * B * vectors.col(i)).norm(), 1e-9 * scale);
    // The smallest eigenvector is the one IRLS uses: it must match to 1e-9 rad
    // when it is well separated from the second.
    if (ref.eigenvalues()(1) > 2.0 * ref.eigenvalues()(0) + 1e-6 * scale) {
      const Vec3 x = vectors.col(0).normalized(), y = ref.eigenvectors().col(0).normalized();
      EXPECT_LT(std::min((x - y).norm(), (x + y).norm()), 1e-9) << "trial " << trial;
    }
  }
}

TEST(GeneralizedEigen3, RejectsIndefiniteB) {
  Vec3 values;
  Mat3 vectors;
  const Mat3 B = Vec3(1.0, -1.0, 1.0).asDiagonal();
  EXPECT_FALSE(detail::generalizedEigen3(Mat3::Identity(), B, values, vectors));
  EXPECT_FALSE(detail::generalizedEigen3(Mat3::Identity(), Mat3::Zero(), values, vectors));
}

namespace {
// The sign test counting every vote (kSignVotesPerCluster per cluster), as resolveSign did
// before it stopped counting once a cluster's majority is decided (votes weighted by the
// line's motion and the share of the window its lines span, as there).
SignDecision resolveSignAllVotes(const WindowObservations& obs, const MotionModel& motion,
                                 const Vec3& v) {
  double votes = 0.0, weights = 0.0;
  long event_balance = 0;
  double t_first = INFINITY, t_last = -INFINITY;
  for (int c : detail::usableClusters(obs, 2)) {
    t_first = std::min(t_first, obs.clusters[c].l1.t);
    t_last = std::max(t_last, obs.clusters[c].l3.t);
  }
  for (int c : detail::usableClusters(obs, 2)) {
    const auto& cl = obs.clusters[c];
    const auto fr = makeClusterFrame(cl, motion);
    const Vec3 ps = fr.Ps * v, pe = fr.Pe * v;
    const size_t stride = std::max<size_t>(1, cl.size() / detail::kSignVotesPerCluster);
    long pos = 0, neg = 0;
    for (size_t k = 0; k < cl.size(); k += stride) {
      Mat3 Rk, Pk;
      motion.pose(cl.times[k], Rk, Pk);
      const Vec3 fp = Rk * cl.bearings[k], pk = Pk * v;
      const double a1 = fr.m1.dot(fp), a3 = fr.m3.dot(fp);
      const double den = a1 * a1 + a3 * a3;
      if (!(den > 1e-24)) continue;
      const double lambda = (a1 * fr.m1.dot(ps - pk) + a3 * fr.m3.dot(pe - pk)) / den;
      if (lambda > 0) ++pos;
      else if (lambda < 0) ++neg;
    }
    if (pos == neg) continue;
    const double share =
        std::clamp((cl.l3.t - cl.l1.t) / (detail::kSignFullSpanShare * (t_last - t_first)), 0.0, 1.0);
    const double w = std::min(lineMotionPx(cl, motion, obs.focal_px, detail::kSignCentroidEvents),
                              detail::kSignFullWeightPx) * share;
    votes += pos > neg ? w : -w;
    weights += w;
    event_balance += pos - neg;
  }
  SignDecision d;
  if (!(weights > 0.0)) return d;
  d.margin = votes / weights;
  d.sign = votes > 0 || (votes == 0 && event_balance >= 0) ? 1 : -1;
  return d;
}
}  // namespace

// The sequential sign test decides exactly as counting every vote: for the
// true direction, its opposite and random directions (mixed votes, ties), on
// scenes with 2 to 6 lines (even numbers of voters can tie).
TEST(SignTest, SequentialCountMatchesFullCount) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> n(0.0, 1.0);
  int ties = 0;
  for (int trial = 0; trial < 60; ++trial) {
    LineSceneOptions o;
    o.n_lines = 2 + trial % 5;
    o.events_per_line = 20 + 30 * (trial % 4);
    const LineSceneTrial tr = generateLineScene(o, rng);
    std::vector<Vec3> dirs{tr.true_direction, -tr.true_direction};
    for (int k = 0; k < 8; ++k) dirs.push_back(Vec3(n(rng), n(rng), n(rng)).normalized());
    for (const Vec3& v : dirs) {
      const SignDecision a = resolveSign(tr.observations, tr.given_motion, v);
      const SignDecision b = resolveSignAllVotes(tr.observations, tr.given_motion, v);
      EXPECT_EQ(a.sign, b.sign) << "trial " << trial;
      EXPECT_EQ(a.margin, b.margin) << "trial " << trial;
      if (b.margin == 0.0) ++ties;
    }
  }
  EXPECT_GT(ties, 0);  // the tie-break by event balance was exercised
}

// The row builder (precomputed cluster terms, no 3x3 products; series
// coefficients below a rotation of 1.5 rad) equals celcRow (B_ref formed
// explicitly, so3's closed forms) to rounding: constant twists from 0 to
// 8 rad/s over the 0.5 s window (up to 4 rad, both coefficient branches) and
// the gyro-integrated model. 1e-12 relative to the row's size allows for the
// different order of operations (and for so3's closed form of C, which loses
// digits to cancellation at small angles). Also the rows formed across a
// cluster's events into packed columns (PackedRows::appendTwistRows).
TEST(ConstraintRows, BuilderMatchesCelcRow) {
  std::mt19937_64 rng(21);
  int packed_clusters = 0;
  for (int trial = 0; trial < 12; ++trial) {
    LineSceneOptions o;
    o.events_per_line = 40;
    o.motion = trial % 3 == 2 ? MotionModelKind::GyroIntegrated : MotionModelKind::ConstantTwist;
    o.omega = Vec3(0.3, -0.2, 1.0).normalized() * std::vector<double>{0.0, 1e-4, 0.5, 2.0, 5.0, 8.0}[trial % 6];
    const LineSceneTrial tr = generateLineScene(o, rng);
    const MotionModel& motion = tr.given_motion;
    for (const auto& cl : tr.observations.clusters) {
      const ClusterFrame frame = makeClusterFrame(cl, motion);
      const detail::ClusterRowTerms terms(frame, motion);
      // The same rows formed across the events, where the series applies.
      const detail::TwistRowConstants* twist = terms.twist();
      std::vector<double> t, fx, fy, fz;
      bool in_range = twist != nullptr;
      for (size_t k = 0; k < cl.size(); ++k) {
        t.push_back(cl.times[k]);
        fx.push_back(cl.bearings[k].x()), fy.push_back(cl.bearings[k].y()), fz.push_back(cl.bearings[k].z());
        if (twist) in_range = in_range && twist->w2 * std::pow(t[k] - twist->t_ref, 2) < detail::kTwistSeriesLimit;
      }
      detail::PackedRows packed(cl.size(), 2);
      if (in_range) {
        ASSERT_TRUE(packed.appendTwistRows(*twist, t.data(), fx.data(), fy.data(), fz.data(), t.size()));
      }
      for (size_t k = 0; k < cl.size(); ++k) {
        const detail::ConstraintRow ref = detail::celcRow(frame, motion, cl.times[k], cl.bearings[k]);
        Vec3 a, n0, n1;
        terms.row(cl.times[k], cl.bearings[k], a, n0, n1);
        const double scale = std::max(ref.a.norm(), ref.N.norm());
        EXPECT_LT((a - ref.a).norm(), 1e-12 * scale) << "trial " << trial << " event " << k;
        EXPECT_LT((n0 - ref.N.row(0).transpose()).norm(), 1e-12 * scale) << "trial " << trial;
        EXPECT_LT((n1 - ref.N.row(1).transpose()).norm(), 1e-12 * scale) << "trial " << trial;
        if (!in_range) continue;
        const double* c = packed.data() + k;
        const size_t s = packed.stride();
        const Vec3 pa(c[0], c[s], c[2 * s]), p0(c[3 * s], c[4 * s], c[5 * s]), p1(c[6 * s], c[7 * s], c[8 * s]);
        EXPECT_LT((pa - ref.a).norm(), 1e-12 * scale) << "trial " << trial << " event " << k;
        EXPECT_LT((p0 - ref.N.row(0).transpose()).norm(), 1e-12 * scale) << "trial " << trial;
        EXPECT_LT((p1 - ref.N.row(1).transpose()).norm(), 1e-12 * scale) << "trial " << trial;
      }
      if (in_range) ++packed_clusters;
    }
  }
  EXPECT_GE(packed_clusters, 20);  // the kernel ran (twists up to 2 rad/s: 30 clusters)
}

// The rows formed across events per piece of a gyro-integrated model
// (PackedRows::appendGyroRows) equal celcRow to rounding, with the velocity
// in the body and in the reference frame: a rate that changes at every
// sample (100 Hz), events spread over several pieces and beyond the samples.
// A run whose rotation leaves the series' range is refused whole.
TEST(ConstraintRows, GyroPiecesMatchCelcRow) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> times;
  std::vector<Vec3> rates;
  for (int i = 0; i <= 40; ++i) {
    times.push_back(0.01 * i);
    rates.push_back(Vec3(0.8, -1.5, 2.0) + Vec3(g(rng), g(rng), g(rng)));
  }
  LineSceneOptions o;
  o.events_per_line = 200;
  const LineSceneTrial tr = generateLineScene(o, rng);
  int runs = 0, first_and_last[2] = {0, 0};
  for (const VelocityFrame frame_kind : {VelocityFrame::Body, VelocityFrame::Reference}) {
    const MotionModel motion = MotionModel::gyroIntegrated(times, rates, 0.2, frame_kind);
    for (const auto& cl : tr.observations.clusters) {
      const ClusterFrame frame = makeClusterFrame(cl, motion);
      const detail::ClusterRowTerms terms(frame, motion);
      ASSERT_EQ(terms.twist(), nullptr);
      // The cluster's events spread over [-0.05, 0.45] s, so that the pieces
      // before the first sample (0 s) and after the last (0.4 s) hold events too.
      std::vector<double> t, fx, fy, fz;
      const double span = cl.times.back() - cl.times.front();
      for (size_t k = 0; k < cl.size(); ++k) {
        t.push_back(-0.05 + 0.5 * (cl.times[k] - cl.times.front()) / span);
        fx.push_back(cl.bearings[k].x()), fy.push_back(cl.bearings[k].y()), fz.push_back(cl.bearings[k].z());
      }
      for (size_t begin = 0, end; begin < t.size(); begin = end) {
        const size_t piece = motion.pieceIndex(t[begin]);
        for (end = begin + 1; end < t.size() && motion.pieceIndex(t[end]) == piece;) ++end;
        first_and_last[0] += piece == 0, first_and_last[1] += piece == times.size();
        detail::PackedRows packed(end - begin, 2);
        ASSERT_TRUE(packed.appendGyroRows(terms.gyroPiece(piece), &t[begin], &fx[begin], &fy[begin],
                                          &fz[begin], end - begin));
        ++runs;
        const size_t s = packed.stride();
        for (size_t k = begin; k < end; ++k) {
          const detail::ConstraintRow ref = detail::celcRow(frame, motion, t[k], Vec3(fx[k], fy[k], fz[k]));
          const double* c = packed.data() + (k - begin);
          const Vec3 pa(c[0], c[s], c[2 * s]), p0(c[3 * s], c[4 * s], c[5 * s]), p1(c[6 * s], c[7 * s], c[8 * s]);
          const double scale = std::max(ref.a.norm(), ref.N.norm());
          EXPECT_LT((pa - ref.a).norm(), 1e-12 * scale) << "event " << k;
          EXPECT_LT((p0 - ref.N.row(0).transpose()).norm(), 1e-12 * scale) << "event " << k;
          EXPECT_LT((p1 - ref.N.row(1).transpose()).norm(), 1e-12 * scale) << "event " << k;
        }
      }
    }
    // An event 2 s after the last sample turns by about 5 rad in its piece:
    // beyond the series, the run is refused and nothing is appended.
    const auto& cl = tr.observations.clusters.front();
    const ClusterFrame frame = makeClusterFrame(cl, motion);
    const detail::ClusterRowTerms terms(frame, motion);
    const double late[2] = {0.45, 2.4}, x[2] = {0.1, 0.1}, y[2] = {0.0, 0.0}, z[2] = {1.0, 1.0};
    detail::PackedRows packed(2, 2);
    EXPECT_FALSE(packed.appendGyroRows(terms.gyroPiece(motion.pieceIndex(2.4)), late, x, y, z, 2));
    EXPECT_EQ(packed.size(), 0u);
  }
  // 5 clusters x 2 frames, each over 42 pieces (200 random times: about 0.4
  // of a piece empty per cluster), the first and the last among them.
  EXPECT_GE(runs, 5 * 2 * 38);
  EXPECT_EQ(first_and_last[0], 10);
  EXPECT_EQ(first_and_last[1], 10);
}
