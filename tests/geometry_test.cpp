// Property tests of SO(3), the motion models and the camera model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "celc/geometry/camera.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/geometry/so3.hpp"

using namespace celc;

namespace {
Vec3 randomVec(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec3(n(rng), n(rng), n(rng)) * scale;
}
}  // namespace

TEST(So3, HatIsCrossProduct) {
  const Vec3 a(1.0, -2.0, 0.5), b(0.3, 0.7, -1.1);
  EXPECT_LT((so3::hat(a) * b - a.cross(b)).norm(), 1e-15);
  EXPECT_LT((so3::vee(so3::hat(a)) - a).norm(), 1e-15);
}

TEST(So3, ExpLogRoundTripAllAngles) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> angle(0.0, M_PI - 1e-6);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 axis = randomVec(rng, 1.0).normalized();
    // Include tiny angles where the Taylor branch is used.
    const double th = (i % 4 == 0) ? std::pow(10.0, -1.0 - i % 9) : angle(rng);
    const Vec3 phi = axis * th;
    const Mat3 R = so3::exp(phi);
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
    EXPECT_LT((so3::log(R) - phi).norm(), 1e-9 * std::max(1.0, th)) << "th=" << th;
  }
}

TEST(So3, ExpMatchesEigenAngleAxis) {
  std::mt19937 rng(2);
  for (int i = 0; i < 100; ++i) {
    const Vec3 phi = randomVec(rng, 1.5);
    const Mat3 ref = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
    EXPECT_LT((so3::exp(phi) - ref).norm(), 1e-13);
  }
}

// J_l(phi) is the derivative of exp at phi: exp(phi + d) ~ exp(J_l(phi) d) exp(phi).
TEST(So3, LeftJacobianAgainstFiniteDifferences) {
  std::mt19937 rng(3);
  const double h = 1e-6;
  for (int i = 0; i < 200; ++i) {
    const Vec3 phi = randomVec(rng, i % 5 == 0 ? 1e-5 : 1.0);
    const Mat3 R = so3::exp(phi);
    Mat3 numeric;
    for (int k = 0; k < 3; ++k) {
      const Vec3 d = Vec3::Unit(k) * h;
      const Mat3 Rp = so3::exp(phi + d), Rm = so3::exp(phi - d);
      numeric.col(k) = (so3::log(Rp * R.transpose()) - so3::log(Rm * R.transpose())) / (2 * h);
    }
    EXPECT_LT((numeric - so3::leftJacobian(phi)).norm(), 1e-7);
    EXPECT_LT((so3::leftJacobian(phi) * so3::leftJacobianInverse(phi) - Mat3::Identity()).norm(),
              1e-10);
  }
}

TEST(So3, SmallAngleSeriesIsContinuous) {
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  // Either side of the switch to the Taylor branch (th^2 = 1e-6).
  for (double th : {0.99e-3, 1.01e-3, 1e-8, 0.0}) {
    const Vec3 phi = axis * th;
    const Mat3 W = so3::hat(phi);
    const Mat3 W2 = W * W;
    const Mat3 exp_series = Mat3::Identity() + W + 0.5 * W2 + W2 * W / 6.0 + W2 * W2 / 24.0;
    const Mat3 jl_series = Mat3::Identity() + 0.5 * W + W2 / 6.0 + W2 * W / 24.0;
    EXPECT_LT((so3::exp(phi) - exp_series).norm(), 1e-13);
    // Reference series truncated after th^3: next term th^4/120 ~ 1e-14 at th = 1e-3.
    EXPECT_LT((so3::leftJacobian(phi) - jl_series).norm(), 5e-14);
  }
}

// The coefficients' three forms (short series, long series, closed form)
// against the closed forms in long double, either side of each switch
// (x = th^2 = 0.1 and 2.25) and far from them. The closed forms lose digits
// at small angles ((th - sin th) / th^3 cancels), so the reference there is
// the long-double series.
TEST(So3, CoefficientsMatchTheirClosedFormsInEveryBranch) {
  const auto reference = [](long double x, long double& A, long double& B, long double& C) {
    if (x < 0.5L) {  // 30 terms of the series, in long double
      long double term_b = 0.5L, term_c = 1.0L / 6.0L;
      B = C = 0.0L;
      for (int k = 0; k < 30; ++k) {
        B += term_b, C += term_c;
        term_b *= -x / ((2 * k + 3) * (2 * k + 4));
        term_c *= -x / ((2 * k + 4) * (2 * k + 5));
      }
    } else {
      const long double th = std::sqrt(x);
      B = (1.0L - std::cos(th)) / x, C = (th - std::sin(th)) / (x * th);
    }
    A = 1.0L - x * C;
  };
  for (double x : {0.0, 1e-12, 1e-6, 0.01, 0.0999, 0.1001, 0.5, 1.0, 2.2499, 2.2501, 4.0, 9.0}) {
    double A, B, C;
    so3::coefficients(x, A, B, C);
    long double a, b, c;
    reference(x, a, b, c);
    EXPECT_NEAR(A, static_cast<double>(a), 4e-16) << x;
    EXPECT_NEAR(B, static_cast<double>(b), 4e-16) << x;
    EXPECT_NEAR(C, static_cast<double>(c), 4e-16) << x;
  }
}

// transposedActions gives R(t)^T x and P(t)^T x as pose() does, for every
// model: the constant twist, and the gyro (a rate varying by sample, beyond
// the ends of its samples, with steps whose angle exceeds the series' range)
// with the velocity in the body or the reference frame.
TEST(MotionModel, TransposedActionsMatchThePose) {
  std::mt19937 rng(7);
  std::vector<double> times;
  std::vector<Vec3> rates;
  for (int i = 0; i <= 12; ++i) {
    times.push_back(0.05 * i);
    rates.push_back(Vec3(1.0, -2.0, 0.5) + randomVec(rng, 1.0));
  }
  // One long step of 0.4 s at ~40 rad/s: its angle is far beyond 1.5 rad.
  times.push_back(1.0);
  rates.push_back(Vec3(30.0, -25.0, 10.0));
  const std::vector<MotionModel> models = {
      MotionModel::constantTwist(Vec3(0.4, -1.2, 2.0), 0.3),
      MotionModel::constantTwist(Vec3(4.0, -3.0, 2.5), 0.3),
      MotionModel::gyroIntegrated(times, rates, 0.3),
      MotionModel::gyroIntegrated(times, rates, 0.3, VelocityFrame::Reference)};
  const Vec3 a = randomVec(rng, 1.0), b = randomVec(rng, 2.0);
  for (const auto& model : models) {
    for (double t : {-0.2, 0.0, 0.03, 0.3, 0.31, 0.47, 0.6, 0.75, 0.99, 1.4}) {
      Mat3 R, P;
      model.pose(t, R, P);
      const auto act = model.transposedActions(t, a, b);
      EXPECT_LT((act.Rt_a - R.transpose() * a).norm(), 1e-13) << t;
      EXPECT_LT((act.Rt_b - R.transpose() * b).norm(), 1e-13) << t;
      EXPECT_LT((act.Pt_a - P.transpose() * a).norm(), 1e-13) << t;
      EXPECT_LT((act.Pt_b - P.transpose() * b).norm(), 1e-13) << t;
    }
  }
}

// The SE(3) exponential of a constant twist: translation is the integral of R(s) v ds.
TEST(MotionModel, ConstantTwistTranslationIsIntegralOfRotatedVelocity) {
  const Vec3 w(0.4, -1.2, 2.0), v(1.0, 2.0, -0.5);
  const auto model = MotionModel::constantTwist(w, 0.3);
  const double t = 1.7;
  const int n = 20000;
  Vec3 integral = Vec3::Zero();
  const double ds = (t - 0.3) / n;
  for (int i = 0; i < n; ++i) integral += so3::exp(w * (ds * (i + 0.5))) * v * ds;
  EXPECT_LT((model.positionMatrix(t) * v - integral).norm(), 1e-7);
  EXPECT_LT((model.rotation(0.3) - Mat3::Identity()).norm(), 1e-15);
}

TEST(MotionModel, GyroIntegratedWithConstantRateMatchesConstantTwist) {
  const Vec3 w(0.5, -0.3, 1.8);
  std::vector<double> times;
  std::vector<Vec3> rates;
  for (int i = 0; i <= 100; ++i) {
    times.push_back(0.01 * i);
    rates.push_back(w);
  }
  const auto gyro = MotionModel::gyroIntegrated(times, rates, 0.25);
  const auto twist = MotionModel::constantTwist(w, 0.25);
  for (double t : {0.0, 0.123, 0.25, 0.777, 1.0, 1.2}) {
    EXPECT_LT((gyro.rotation(t) - twist.rotation(t)).norm(), 1e-12) << t;
  }
  EXPECT_LT((gyro.meanOmega(0.1, 0.9) - w).norm(), 1e-10);
  // Body-frame velocity (the default): P(t) = integral of R = J_l(w tau) tau, the twist's.
  for (double t : {0.0, 0.123, 0.25, 0.777, 1.0, 1.2}) {
    Mat3 R, P;
    gyro.pose(t, R, P);
    EXPECT_LT((P - twist.positionMatrix(t)).norm(), 1e-12) << t;
    EXPECT_LT((gyro.positionMatrix(t) - P).norm(), 1e-15) << t;
    EXPECT_LT((R - gyro.rotation(t)).norm(), 1e-15) << t;
  }
  // Reference-frame velocity (the peers' protocol): P(t) = tau I.
  const auto reference = MotionModel::gyroIntegrated(times, rates, 0.25, VelocityFrame::Reference);
  EXPECT_LT((reference.positionMatrix(0.75) - 0.5 * Mat3::Identity()).norm(), 1e-15);
  EXPECT_LT((reference.rotation(0.777) - twist.rotation(0.777)).norm(), 1e-12);
  EXPECT_EQ(reference.withOmegaOffset(Vec3::Zero()).velocityFrame(), VelocityFrame::Reference);
}

TEST(MotionModel, GyroIntegratedFollowsVaryingRate) {
  // w(t) = a + b t about a fixed axis: angle = a t + b t^2 / 2 exactly.
  const Vec3 axis = Vec3(1.0, 2.0, -1.0).normalized();
  const double a = 1.0, b = 3.0;
  std::vector<double> times;
  std::vector<Vec3> rates;
  for (int i = 0; i <= 50; ++i) {
    times.push_back(0.02 * i);
    rates.push_back(axis * (a + b * times.back()));
  }
  const auto gyro = MotionModel::gyroIntegrated(times, rates, 0.0);
  for (double t : {0.13, 0.5, 0.99}) {
    const Mat3 expected = so3::exp(axis * (a * t + 0.5 * b * t * t));
    EXPECT_LT((gyro.rotation(t) - expected).norm(), 1e-12) << t;
  }
  // P(t) = integral of R(s) ds from t_ref = 0, by Simpson's rule on a fine grid
  // of the exact rotation (error ~1e-12 at 2000 steps).
  for (double t : {0.13, 0.5, 0.99}) {
    const int n = 2000;
    Mat3 integral = Mat3::Zero();
    for (int k = 0; k <= n; ++k) {
      const double s = t * k / n, weight = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      integral += weight * so3::exp(axis * (a * s + 0.5 * b * s * s));
    }
    integral *= t / (3.0 * n);
    // Inside a step the model turns at the mean rate of the step's start and t,
    // off the true angle by at most b dt^2 / 8 = 1.5e-4 rad (dt = 20 ms); the
    // integral of R is then off by at most that times t (|R - R'| <= sqrt(2) angle).
    EXPECT_LT((gyro.positionMatrix(t) - integral).norm(), 1.5e-4 * std::sqrt(2.0) * t) << t;
  }
}

// pieceIndex guesses the sample after t from the mean step and searches
// where the guess misses: it must give upper_bound's index everywhere, on a
// jittered clock, across a 50 ms gap (the guess then far off), at the
// sample times themselves, outside the samples, and for NaN.
TEST(MotionModel, PieceIndexIsTheFirstSampleAfterT) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.3e-3, 0.3e-3), unit(0.0, 1.0);
  std::vector<double> times;
  std::vector<Vec3> rates;
  double t = 10.0;
  for (int i = 0; i < 400; ++i) {
    times.push_back(t);
    rates.push_back(Vec3(0.1, -0.2, 0.3));
    t += (i == 200 ? 0.05 : 1e-3) + jitter(rng);
  }
  const MotionModel m = MotionModel::gyroIntegrated(times, rates, 10.1);
  auto want = [&](double x) {
    if (!(x > times.front())) return std::size_t{0};
    return static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), x) - times.begin());
  };
  std::vector<double> asked = {times.front() - 1.0, times.back(), times.back() + 1.0, std::nextafter(times.back(), 0.0)};
  for (double s : times) asked.insert(asked.end(), {s, std::nextafter(s, 0.0), std::nextafter(s, 1e9)});
  for (int k = 0; k < 20000; ++k) asked.push_back(times.front() - 0.01 + (times.back() - times.front() + 0.02) * unit(rng));
  for (double x : asked) EXPECT_EQ(m.pieceIndex(x), want(x)) << "t = " << x;
  EXPECT_EQ(m.pieceIndex(NAN), times.size());
}

TEST(Camera, DistortUndistortRoundTrip) {
  CameraModel cam;
  for (auto model : {DistortionModel::RadTan, DistortionModel::Equidistant}) {
    cam.distortion = model;
    cam.coeffs = model == DistortionModel::RadTan
                     ? std::array<double, 5>{-0.35, 0.15, 1e-3, -5e-4, -0.02}
                     : std::array<double, 5>{-0.02, 0.01, -0.005, 0.001, 0.0};
    for (double x = -0.5; x <= 0.5; x += 0.1)
      for (double y = -0.4; y <= 0.4; y += 0.1) {
        const Vec2 p(x, y);
        EXPECT_LT((cam.undistort(cam.distort(p)) - p).norm(), 1e-10) << toString(model);
      }
  }
  EXPECT_EQ(parseDistortionModel("fisheye"), DistortionModel::Equidistant);
  EXPECT_THROW(parseDistortionModel("banana"), std::invalid_argument);
}
