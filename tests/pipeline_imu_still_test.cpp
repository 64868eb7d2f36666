// The still-second detector (pipeline/imu_still.hpp): rest is rest, a
// steady rotation or a slow drift is not; and the summary's kept windows.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "celc/eval/run_tables.hpp"
#include "celc/pipeline/imu_still.hpp"
#include "celc/pipeline/run_config.hpp"

using namespace celc;

namespace {

// A DAVIS-like IMU stream at 1 kHz: the camera turns at the constant body rate
// `omega` [rad/s] from the identity, gravity (0, 9.81, 0) in the world frame;
// the gyro reads omega + bias + noise (0.003 rad/s per axis), the
// accelerometer the body-frame gravity (its specific force) + noise
// (0.05 m/s^2 per axis), or zeros without an accelerometer.
std::vector<ImuSample> steadyImu(const Vec3& omega, const Vec3& bias, double seconds, unsigned seed,
                                 bool accelerometer = true) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gyro_noise(0.0, 0.003), accel_noise(0.0, 0.05);
  const Vec3 g_world(0.0, 9.81, 0.0);
  std::vector<ImuSample> imu;
  for (int k = 0; k < static_cast<int>(seconds * 1000.0); ++k) {
    ImuSample s;
    s.t = 10.0 + k * 1e-3;  // a recording's clock need not start at 0
    const double turned = omega.norm() * (s.t - 10.0);
    const Mat3 R_world_body =
        omega.norm() > 0 ? Mat3(Eigen::AngleAxisd(turned, omega.normalized())) : Mat3(Mat3::Identity());
    s.gyro = omega + bias + Vec3(gyro_noise(rng), gyro_noise(rng), gyro_noise(rng));
    if (accelerometer)
      s.accel = R_world_body.transpose() * g_world + Vec3(accel_noise(rng), accel_noise(rng), accel_noise(rng));
    imu.push_back(s);
  }
  return imu;
}

const Vec3 kBoxesBias(-0.061, -0.083, -0.005);  // the shared DAVIS240C boxes recording's, about 6 deg/s

}  // namespace

// True rest with a bias of 6 deg/s: the first second is still, its mean is
// the bias within the noise (0.003 / sqrt(1000) = 1e-4 rad/s per axis; 5e-4
// allowed) and significant; a bias of 0.001 rad/s is found but within the
// noise floor (kStillBiasMinRate).
TEST(ImuStill, TrueRestWithABiasIsStill) {
  const StillSpan st = findFirstStill(steadyImu(Vec3::Zero(), kBoxesBias, 3.0, 11));
  ASSERT_TRUE(st.found) << st.refused;
  EXPECT_NEAR(st.t0, 10.0, 1e-9);
  EXPECT_NEAR(st.t1, 11.0, 1e-9);
  EXPECT_GE(st.samples, 990);
  EXPECT_LT((st.gyro_mean - kBoxesBias).cwiseAbs().maxCoeff(), 5e-4);
  EXPECT_LT(st.gyro_std.maxCoeff(), 0.004);
  EXPECT_LT(st.accel_turn, 0.005);
  EXPECT_TRUE(st.has_accel);
  EXPECT_TRUE(st.warning.empty());
  EXPECT_TRUE(st.refused.empty());
  EXPECT_TRUE(st.significant(kStillBiasZ, kStillBiasMinRate));

  const StillSpan small = findFirstStill(steadyImu(Vec3::Zero(), Vec3(0.001, 0.0, 0.0), 3.0, 12));
  ASSERT_TRUE(small.found);
  EXPECT_FALSE(small.significant(kStillBiasZ, kStillBiasMinRate));
}

// A camera turning at a constant 0.95 rad/s has a steady gyro (low variance)
// but turns gravity in its frame: about axes across gravity no span is
// still, and the reason names the accelerometer's direction; about the
// gravity axis itself the accelerometer sees nothing and the rate (above a
// bias's 0.35 rad/s) refuses it.
TEST(ImuStill, ConstantRotationIsNotStill) {
  const std::vector<Vec3> axes = {Vec3::UnitX(), Vec3::UnitZ(), Vec3(1, 1, 1).normalized(), Vec3(1, 0.2, -1).normalized(),
                       Vec3(-0.57, -0.61, -0.37).normalized()};
  unsigned seed = 20;
  for (const Vec3& axis : axes) {
    for (const Vec3& bias : std::vector<Vec3>{Vec3::Zero(), kBoxesBias}) {
      const StillSpan st = findFirstStill(steadyImu(0.95 * axis, bias, 3.0, ++seed));
      EXPECT_FALSE(st.found) << "axis " << axis.transpose() << ": still at " << st.t0;
      EXPECT_NE(st.refused.find("the accelerometer direction turns"), std::string::npos) << st.refused;
      EXPECT_NE(st.refused.find("the first span [10.000, 11.000] s"), std::string::npos) << st.refused;
    }
  }
  const StillSpan about_gravity = findFirstStill(steadyImu(Vec3(0, 0.95, 0), Vec3::Zero(), 3.0, 40));
  EXPECT_FALSE(about_gravity.found);
  EXPECT_NE(about_gravity.refused.find("more than a bias"), std::string::npos) << about_gravity.refused;
  EXPECT_EQ(about_gravity.refused.find("accelerometer direction"), std::string::npos) << about_gravity.refused;
}

// A slow drift of 0.05 rad/s (3 deg/s, as small as a bias) turns gravity by
// 0.05 rad a second: not still, whatever the axis across gravity; nor 0.02
// rad/s.
TEST(ImuStill, SlowDriftIsNotStill) {
  unsigned seed = 50;
  for (const Vec3& axis : std::vector<Vec3>{Vec3::UnitX(), Vec3::UnitZ(), Vec3(1, 1, 0).normalized()})
    for (double rate : {0.05, 0.02}) {
      const StillSpan st = findFirstStill(steadyImu(rate * axis, kBoxesBias, 4.0, ++seed));
      EXPECT_FALSE(st.found) << "axis " << axis.transpose() << " at " << rate << " rad/s: still at " << st.t0
                             << ", turn " << st.accel_turn;
      EXPECT_NE(st.refused.find("the accelerometer direction turns"), std::string::npos) << st.refused;
    }
}

// Without an accelerometer (zeros) rest is judged from the gyro alone: found,
// with a warning that says so; a steady 0.95 rad/s is still refused by its
// rate.
TEST(ImuStill, RestWithoutAccelerometerIsStillWithAWarning) {
  const StillSpan st = findFirstStill(steadyImu(Vec3::Zero(), kBoxesBias, 2.0, 60, false));
  ASSERT_TRUE(st.found) << st.refused;
  EXPECT_FALSE(st.has_accel);
  EXPECT_NE(st.warning.find("no accelerometer"), std::string::npos) << st.warning;
  EXPECT_LT((st.gyro_mean - kBoxesBias).cwiseAbs().maxCoeff(), 5e-4);
  const StillSpan turning = findFirstStill(steadyImu(Vec3(0.95, 0, 0), Vec3::Zero(), 2.0, 61, false));
  EXPECT_FALSE(turning.found);
  EXPECT_FALSE(turning.warning.empty());
  EXPECT_NE(turning.refused.find("more than a bias"), std::string::npos) << turning.refused;
}

// A hand-held start is refused for its varying gyro; the rest after it is
// found; a stream shorter than a span says so.
TEST(ImuStill, RefusalsNameTheReason) {
  std::vector<ImuSample> imu = steadyImu(Vec3::Zero(), kBoxesBias, 3.0, 70);
  for (ImuSample& s : imu)
    if (s.t < 11.2) s.gyro += Vec3(0.4 * std::sin(20.0 * s.t), 0.0, 0.0);
  StillSpan st = findFirstStill(imu);
  ASSERT_TRUE(st.found);
  EXPECT_NEAR(st.t0, 11.25, 1e-6);
  imu.resize(1500);
  st = findFirstStill(imu);
  EXPECT_FALSE(st.found);
  EXPECT_NE(st.refused.find("the gyro varies"), std::string::npos) << st.refused;
  imu.resize(500);
  st = findFirstStill(imu);
  EXPECT_FALSE(st.found);
  EXPECT_NE(st.refused.find("less than a span"), std::string::npos) << st.refused;
  EXPECT_FALSE(findFirstStill({}).found);
}

// The summary names the windows it keeps, as ranges.
TEST(ImuStill, SummaryNamesTheKeptWindows) {
  EXPECT_EQ(windowRanges({}), "");
  EXPECT_EQ(windowRanges({4}), "4");
  EXPECT_EQ(windowRanges({0, 1, 2, 3, 7, 9, 10}), "0-3, 7, 9-10");
  EXPECT_EQ(windowRanges({0, 2, 4, 6}, 2), "0, 2, ... (4 windows)");
  std::vector<WindowsCsvRow> rows;
  for (int w = 0; w < 5; ++w) {
    WindowsCsvRow r;
    r.window = w;
    r.method = "celc_ml";
    r.status = w == 1 ? "degenerate" : "ok";
    r.sigma_deg = w == 3 ? 9.0 : 2.0;
    rows.push_back(r);
  }
  const auto s = summarize(rows, 5.0);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].kept, 3);
  EXPECT_EQ(s[0].kept_windows, (std::vector<std::int64_t>{0, 2, 4}));
  EXPECT_NE(summaryMarkdown("t", s).find("| 0, 2, 4 |"), std::string::npos) << summaryMarkdown("t", s);
}
