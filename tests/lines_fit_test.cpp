// Boundary-line fitting (celc/lines/line_fit.hpp): accuracy, robustness,
// sliding intervals, quality flags, degenerate input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "celc/lines/line_fit.hpp"

namespace celc {
namespace {

constexpr double kFocal = 200.0;

double angleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::min(1.0, std::fabs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

// A line in normalised coordinates through p with direction d, moving with
// normal velocity `speed` [normalised units/s]; events uniformly in time.
struct MovingLine {
  Vec2 p{0.05, -0.1};
  Vec2 d{std::cos(0.4), std::sin(0.4)};
  double speed = 0.2;
  Vec2 nrm() const { return Vec2(-d.y(), d.x()); }
  Vec3 normalAt(double t) const {
    const Vec2 q = p + nrm() * speed * t;
    return Vec3(q.x(), q.y(), 1.0).cross(Vec3(d.x(), d.y(), 0.0)).normalized();
  }
  void sample(int n, double t0, double t1, double noise_px, unsigned seed, std::vector<double>& times,
              std::vector<Vec3>& bearings) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::normal_distribution<double> N(0.0, noise_px / kFocal);
    for (int i = 0; i < n; ++i) {
      const double t = t0 + (t1 - t0) * (i + 0.5) / n;
      const Vec2 q = p + nrm() * (speed * t + N(rng)) + d * (U(rng) - 0.5) * 0.4;
      times.push_back(t);
      bearings.emplace_back(q.x(), q.y(), 1.0);
    }
  }
};

TEST(LinesFit, ExactPointsGiveTheLine) {
  const MovingLine line{Vec2(0.1, 0.2), Vec2(1.0, 0.0), 0.0};
  std::vector<double> t;
  std::vector<Vec3> b;
  line.sample(50, 0.0, 0.001, 0.0, 1, t, b);
  const FittedLine f = fitLine(b, t, kFocal);
  ASSERT_EQ(f.status, LineFitStatus::Ok);
  EXPECT_LT(angleDeg(f.line.normal, line.normalAt(0.0)), 1e-3);
  EXPECT_NEAR(f.line.normal.norm(), 1.0, 1e-12);
  EXPECT_LT(f.rms_px, 1e-3);
  // Points spread over 0.4 normalised units along the line: about 80 px.
  EXPECT_GT(f.length_px, 70.0);
  EXPECT_LT(f.length_px, 81.0);
  EXPECT_DOUBLE_EQ(f.t_first, t.front());
  EXPECT_DOUBLE_EQ(f.t_last, t.back());
}

TEST(LinesFit, HuberResistsOutliers) {
  const MovingLine line{Vec2(-0.1, 0.05), Vec2(std::cos(1.0), std::sin(1.0)), 0.0};
  std::vector<double> t;
  std::vector<Vec3> b;
  line.sample(200, 0.0, 0.005, 0.5, 2, t, b);
  // 10% outliers 15-25 px off the line, all on one side.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(15.0, 25.0);
  for (size_t i = 0; i < b.size(); i += 10) {
    const Vec2 off = line.nrm() * U(rng) / kFocal;
    b[i] += Vec3(off.x(), off.y(), 0.0);
  }
  const FittedLine f = fitLine(b, t, kFocal);
  // Least squares would shift the line by ~2 px; Huber stays within ~0.5 deg.
  EXPECT_LT(angleDeg(f.line.normal, line.normalAt(0.0)), 0.5);
}

TEST(LinesFit, EndLinesAtClusterEnds) {
  const MovingLine line;
  std::vector<double> t;
  std::vector<Vec3> b;
  line.sample(2000, 0.0, 0.1, 0.5, 4, t, b);  // times 0..0.1 s
  LineFitOptions opt;  // the paper's: still lines over 5 ms intervals
  opt.model = LineModel::Static;
  opt.interval_fraction = 0.0;
  const ClusterLines cl = fitClusterLines(t, b, kFocal, opt);
  ASSERT_TRUE(cl.ok());
  EXPECT_FALSE(cl.l1.slid);
  EXPECT_FALSE(cl.l3.slid);
  EXPECT_GE(cl.l1.t_first, t.front());
  EXPECT_LT(cl.l1.t_last, t.front() + 0.005);
  EXPECT_GT(cl.l3.t_first, t.back() - 0.005);
  EXPECT_LE(cl.l3.t_last, t.back());
  EXPECT_NEAR(cl.l2.line.t, 0.5 * (t.front() + t.back()), 0.001);
  // Each line matches the true line at its own (mean) time.
  for (const FittedLine* f : {&cl.l1, &cl.l2, &cl.l3}) {
    EXPECT_EQ(f->status, LineFitStatus::Ok);
    EXPECT_TRUE(f->rms_ok && f->length_ok);
    EXPECT_LT(angleDeg(f->line.normal, line.normalAt(f->line.t)), 0.3);
    EXPECT_LT(f->rms_px, 1.0);
    EXPECT_GE(f->line.t, f->t_first);
    EXPECT_LE(f->line.t, f->t_last);
  }
  EXPECT_GT(cl.l3.line.t, cl.l1.line.t);
}

TEST(LinesFit, SparseEndSlidesTowardCentre) {
  const MovingLine line;
  std::vector<double> t, t2;
  std::vector<Vec3> b, b2;
  line.sample(3, 0.0, 0.004, 0.3, 5, t, b);        // 3 events in the first 4 ms
  line.sample(1000, 0.02, 0.1, 0.3, 6, t2, b2);    // then dense from 20 ms
  t.insert(t.end(), t2.begin(), t2.end());
  b.insert(b.end(), b2.begin(), b2.end());
  LineFitOptions opt;
  opt.model = LineModel::Static;
  opt.interval_fraction = 0.0;
  opt.min_events = 8;
  const ClusterLines cl = fitClusterLines(t, b, kFocal, opt);
  ASSERT_EQ(cl.l1.status, LineFitStatus::Ok);
  EXPECT_TRUE(cl.l1.slid);
  EXPECT_GT(cl.l1.t_begin, t.front());
  EXPECT_GE(cl.l1.n_events, opt.min_events);
  EXPECT_GE(cl.l1.t_first, cl.l1.t_begin);
  EXPECT_LT(cl.l1.t_last, cl.l1.t_end);
  EXPECT_LT(angleDeg(cl.l1.line.normal, line.normalAt(cl.l1.line.t)), 0.5);
  EXPECT_FALSE(cl.l3.slid);
}

// The moving model (the default): a line moving 0.2 normalised units/s
// (40 px/s) is fitted exactly at the interval's mean time however long the
// interval, and a sparse end grows its interval instead of being rejected.
TEST(LinesFit, MovingLineIsExactAtItsTimeAndSparseEndsGrow) {
  const MovingLine line;
  std::vector<double> t;
  std::vector<Vec3> b;
  line.sample(2000, 0.0, 0.5, 0.0, 4, t, b);
  for (double fraction : {0.05, 0.2, 0.5}) {
    LineFitOptions opt;
    opt.interval_fraction = fraction;
    const ClusterLines cl = fitClusterLines(t, b, kFocal, opt);
    ASSERT_TRUE(cl.ok()) << fraction;
    for (const FittedLine* f : {&cl.l1, &cl.l2, &cl.l3}) {
      EXPECT_EQ(f->status, LineFitStatus::Ok);
      // Noise-free: exact to rounding (a still-line fit is off by the motion).
      EXPECT_LT(angleDeg(f->line.normal, line.normalAt(f->line.t)), 1e-6) << fraction;
      EXPECT_LT(f->rms_px, 1e-6);
      EXPECT_GE(f->line.t, f->t_first);
      EXPECT_LE(f->line.t, f->t_last);
    }
    // Interval of the requested share; the line at its events' mean time.
    EXPECT_NEAR(cl.l1.t_end - cl.l1.t_begin, fraction * (t.back() - t.front()), 1e-12);
    EXPECT_NEAR(cl.l1.line.t, 0.5 * (cl.l1.t_first + cl.l1.t_last), 0.01 * fraction);
  }
  // 20 events over 0.5 s with 0.5 px noise: the 20% intervals (about 4
  // events) grow until they hold min_events = 8.
  std::vector<double> ts;
  std::vector<Vec3> bs;
  line.sample(20, 0.0, 0.5, 0.5, 5, ts, bs);
  const ClusterLines sparse = fitClusterLines(ts, bs, kFocal, LineFitOptions{});
  ASSERT_TRUE(sparse.ok());
  EXPECT_TRUE(sparse.l1.slid && sparse.l3.slid);
  EXPECT_GE(sparse.l1.n_events, 8);
  EXPECT_GT(sparse.l3.line.t - sparse.l1.line.t, 0.1);
  // A 0.5 px error at the ends of a 64 px line: about 1 deg.
  EXPECT_LT(angleDeg(sparse.l1.line.normal, line.normalAt(sparse.l1.line.t)), 2.0);
  EXPECT_LT(angleDeg(sparse.l3.line.normal, line.normalAt(sparse.l3.line.t)), 2.0);
}

// The moving model removes the rotation before fitting: a still 3D line seen
// by a camera rotating at 3 rad/s is fitted exactly over a long interval.
TEST(LinesFit, MovingModelRemovesTheRotation) {
  const Vec3 w(0.5, -2.0, 2.2);  // |w| = 3 rad/s
  const MotionModel motion = MotionModel::constantTwist(w, 0.0);
  const Vec3 P(0.3, -0.2, 4.0), d = Vec3(1.0, 0.4, 0.2).normalized();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-0.8, 0.8);
  std::vector<double> t;
  std::vector<Vec3> b;
  for (int i = 0; i < 600; ++i) {
    const double ti = 0.3 * i / 599.0;
    const Vec3 Xc = motion.rotation(ti).transpose() * (P + U(rng) * d);  // camera still at the origin
    t.push_back(ti);
    b.push_back(Xc / Xc.z());
  }
  auto trueNormal = [&](double ti) {
    const Mat3 Rt = motion.rotation(ti).transpose();
    return Vec3((Rt * P).cross(Rt * d));
  };
  LineFitOptions opt;
  opt.interval_fraction = 0.5;  // 0.45 rad of rotation inside each interval
  const ClusterLines moving = fitClusterLines(t, b, kFocal, opt, &motion);
  ASSERT_TRUE(moving.ok());
  EXPECT_LT(angleDeg(moving.l1.line.normal, trueNormal(moving.l1.line.t)), 1e-6);
  EXPECT_LT(angleDeg(moving.l3.line.normal, trueNormal(moving.l3.line.t)), 1e-6);
  // Without the rotation, a normal linear in time absorbs it only to first order.
  const ClusterLines blind = fitClusterLines(t, b, kFocal, opt);
  EXPECT_GT(angleDeg(blind.l1.line.normal, trueNormal(blind.l1.line.t)), 0.1);
}

TEST(LinesFit, QualityFlags) {
  // Scattered points: poor fit.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.1, 0.1);
  std::vector<double> t;
  std::vector<Vec3> b;
  for (int i = 0; i < 200; ++i) t.push_back(i * 1e-4), b.emplace_back(U(rng), U(rng), 1.0);
  LineFitOptions opt;
  ClusterLines cl = fitClusterLines(t, b, kFocal, opt);
  EXPECT_EQ(cl.l1.status, LineFitStatus::PoorFit);
  EXPECT_FALSE(cl.l1.rms_ok);
  EXPECT_FALSE(cl.ok());
  // A short blob (1 px long): poor fit by length, not by residual.
  t.clear(), b.clear();
  for (int i = 0; i < 200; ++i)
    t.push_back(i * 1e-4), b.emplace_back((i % 3) * 0.4 / kFocal, 0.0, 1.0);
  cl = fitClusterLines(t, b, kFocal, opt);
  EXPECT_EQ(cl.l1.status, LineFitStatus::PoorFit);
  EXPECT_TRUE(cl.l1.rms_ok);
  EXPECT_FALSE(cl.l1.length_ok);
  opt.min_length_px = 0.0;
  EXPECT_EQ(fitClusterLines(t, b, kFocal, opt).l1.status, LineFitStatus::Ok);
}

TEST(LinesFit, DegenerateInput) {
  LineFitOptions opt;
  // Too few events.
  std::vector<double> t{0.0, 0.001, 0.002};
  std::vector<Vec3> b(3, Vec3(0.0, 0.0, 1.0));
  EXPECT_EQ(fitClusterLines(t, b, kFocal, opt).l1.status, LineFitStatus::TooFewEvents);
  // Size mismatch, unsorted times, bad focal length: no line, no crash.
  const MovingLine line;
  std::vector<double> tt;
  std::vector<Vec3> bb;
  line.sample(500, 0.0, 0.05, 0.3, 8, tt, bb);
  EXPECT_FALSE(fitClusterLines(tt, std::vector<Vec3>(bb.begin(), bb.end() - 1), kFocal, opt).ok());
  std::vector<double> shuffled = tt;
  std::swap(shuffled[3], shuffled[400]);
  EXPECT_FALSE(fitClusterLines(shuffled, bb, kFocal, opt).ok());
  EXPECT_FALSE(fitClusterLines(tt, bb, 0.0, opt).ok());
  // NaN bearings.
  std::vector<Vec3> nan = bb;
  for (auto& x : nan) x.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(fitClusterLines(tt, nan, kFocal, opt).ok());
  // All events at one time: no interval.
  EXPECT_FALSE(fitClusterLines(std::vector<double>(tt.size(), 5.0), bb, kFocal, opt).ok());
  // Huge timestamps and a tiny duration: terminates.
  std::vector<double> big(tt.size());
  for (size_t i = 0; i < tt.size(); ++i) big[i] = 1.7e9 + i * 1e-9;
  (void)fitClusterLines(big, bb, kFocal, opt);
  // Options.
  opt.min_events = 1;
  EXPECT_NE(opt.validate().find("min_events"), std::string::npos);
  opt = LineFitOptions{};
  opt.min_length_px = -1.0;
  EXPECT_NE(opt.validate().find("min_length_px"), std::string::npos);
  EXPECT_TRUE(LineFitOptions{}.validate().empty());
}

TEST(LinesFit, AttachStoresLines) {
  const MovingLine line;
  ClusterObservation c;
  line.sample(1500, 0.0, 0.08, 0.4, 9, c.times, c.bearings);
  ASSERT_TRUE(attachFittedLines(c, kFocal, LineFitOptions{}));
  EXPECT_TRUE(c.has_l2);
  EXPECT_LT(angleDeg(c.l1.normal, line.normalAt(c.l1.t)), 0.3);
  EXPECT_LT(angleDeg(c.l3.normal, line.normalAt(c.l3.t)), 0.3);
  EXPECT_LT(c.l1.t, c.l3.t);
  ClusterObservation empty;
  EXPECT_FALSE(attachFittedLines(empty, kFocal, LineFitOptions{}));
}

}  // namespace
}  // namespace celc
