// The accelerometer as the camera's acceleration over a window
// (pipeline/accelerometer.hpp), on the rendering simulator's IMU: a camera at
// rest for a second, then turning with a constant, world-fixed acceleration.
#include <gtest/gtest.h>

#include <cmath>

#include "celc/geometry/so3.hpp"
#include "celc/pipeline/accelerometer.hpp"
#include "celc/pipeline/imu_still.hpp"
#include "celc/sim/render_sequence.hpp"
#include "celc/sim/scene_trajectory.hpp"

using namespace celc;

namespace {

/// Turning at w = (0.4, -0.9, 0.3) rad/s (1 rad/s) from a pose 0.5 rad off
/// the world's, accelerating at a = (1.5, -0.3, 1.2) m/s^2 (camera frame at
/// t = 0, fixed in the world).
TrajectorySpec acceleratingSpec() {
  TrajectorySpec s;
  s.kind = TrajectoryKind::ConstantAcceleration;
  s.v = Vec3(1.2, -0.2, 0.9);
  s.w = Vec3(0.4, -0.9, 0.3);
  s.acceleration = Vec3(1.5, -0.3, 1.2);
  s.initial.R = so3::exp(Vec3(0.3, 0.2, -0.35));
  return s;
}

/// The true acceleration in the camera frame at t: exp(w t)^T a.
Vec3 trueAcceleration(const TrajectorySpec& s, double t) { return so3::exp(s.w * t).transpose() * s.acceleration; }

struct Recording {
  std::vector<ImuSample> imu;
  StillSpan still;
};

Recording record(const ImuOptions& o) {
  const Trajectory tr(acceleratingSpec(), 2.0);
  Recording r;
  r.imu = simulateImu(tr, o, -o.still_before_s, 1.0, 5);
  r.still = findFirstStill(r.imu);
  return r;
}

ImuOptions imuOptions() {
  ImuOptions o;
  o.still_before_s = 1.0;
  o.R_cam_imu = so3::exp(Vec3(0.0, M_PI / 2, 0.1));
  return o;
}

}  // namespace

// Noise-free IMU: gravity and the window's acceleration come back to the
// integration's error (the trapezoidal rule at 1 kHz over 1.5 s turns
// gravity by ~1e-7 rad; 1e-3 m/s^2 allowed), in the frame at t_ref; sigma is
// the bias term alone (sqrt(2) x 0.05).
TEST(Accelerometer, NoiseFreeWindowsGiveTheTrueAcceleration) {
  ImuOptions o = imuOptions();
  o.gyro_noise = o.accel_noise = 0.0;
  const Recording r = record(o);
  ASSERT_TRUE(r.still.found) << r.still.refused;
  const AccelerometerTrack track(r.imu, o.R_cam_imu, 0.0, r.still, AccelerometerOptions{});
  ASSERT_FALSE(track.empty());
  const TrajectorySpec s = acceleratingSpec();
  for (double t0 : {0.0, 0.25, 0.6}) {
    const double t_ref = t0 + 0.1;
    const MeasuredAcceleration m = track.window(t0, t0 + 0.3, t_ref);
    ASSERT_TRUE(m.valid) << "t0=" << t0;
    EXPECT_LT((m.a - trueAcceleration(s, t_ref)).norm(), 1e-3) << "t0=" << t0 << " a=" << m.a.transpose();
    EXPECT_NEAR(m.sigma, std::sqrt(2.0) * 0.05, 1e-6);
    EXPECT_NEAR(m.t0, t0, 1e-9);          // the first sample averaged
    EXPECT_NEAR(m.t1, t0 + 0.299, 1e-9);  // the last before t0 + 0.3 at 1 kHz
  }
}

// A MEMS sensor's noise (4e-3 m/s^2/sqrt(Hz)) and bias (0.04, -0.05, 0.03
// m/s^2, about the assumed 0.05 per axis): every window's error is within 3
// of its sigmas per axis.
TEST(Accelerometer, NoisyBiasedWindowsAreWithinTheirSigma) {
  ImuOptions o = imuOptions();
  o.accel_noise = 4e-3;
  o.accel_bias = Vec3(0.04, -0.05, 0.03);
  const Recording r = record(o);
  ASSERT_TRUE(r.still.found) << r.still.refused;
  const AccelerometerTrack track(r.imu, o.R_cam_imu, 0.0, r.still, AccelerometerOptions{});
  const TrajectorySpec s = acceleratingSpec();
  for (double t0 = 0.0; t0 < 0.7; t0 += 0.1) {
    const MeasuredAcceleration m = track.window(t0, t0 + 0.3, t0);
    ASSERT_TRUE(m.valid);
    EXPECT_LT((m.a - trueAcceleration(s, t0)).cwiseAbs().maxCoeff(), 3.0 * m.sigma) << "t0=" << t0;
  }
}

// No gravity, no answer: without a still span, without an accelerometer
// (every sample 0), or for a reference time or window outside the samples.
TEST(Accelerometer, WithoutGravityOrSamplesThereIsNoAnswer) {
  ImuOptions o = imuOptions();
  Recording r = record(o);
  const AccelerometerTrack track(r.imu, o.R_cam_imu, 0.0, r.still, AccelerometerOptions{});
  EXPECT_FALSE(track.window(0.2, 0.4, 5.0).valid);
  EXPECT_FALSE(track.window(3.0, 3.5, 0.9).valid);
  EXPECT_FALSE(track.window(0.4, 0.2, 0.3).valid);

  StillSpan none = r.still;
  none.found = false;
  EXPECT_TRUE(AccelerometerTrack(r.imu, o.R_cam_imu, 0.0, none, AccelerometerOptions{}).empty());

  for (ImuSample& s : r.imu) s.accel = Vec3::Zero();
  const StillSpan gyro_only = findFirstStill(r.imu);
  EXPECT_FALSE(gyro_only.has_accel);
  EXPECT_TRUE(AccelerometerTrack(r.imu, o.R_cam_imu, 0.0, gyro_only, AccelerometerOptions{}).empty());

  AccelerometerOptions bad;
  bad.bias_m_s2 = -1.0;
  EXPECT_NE(bad.validate().find("accel_bias_m_s2"), std::string::npos);
}

// Hostile IMU streams: NaN and infinite samples, repeated and backward
// timestamps, a huge reading. The track skips what it cannot use, never
// answers with a non-finite value; a window without two usable samples, or
// beyond a gap in the gyro from the still span, has no answer.
TEST(Accelerometer, BrokenSamplesAreSkippedNeverAnswered) {
  ImuOptions o = imuOptions();
  Recording r = record(o);
  ASSERT_TRUE(r.still.found);
  std::vector<ImuSample> broken = r.imu;
  for (std::size_t k = 1500; k < 1600; ++k) broken[k].accel.x() = NAN;       // inside [0.5, 0.6)
  for (std::size_t k = 1600; k < 1650; ++k) broken[k].gyro.y() = INFINITY;   // [0.6, 0.65)
  for (std::size_t k = 1700; k < 1710; ++k) broken[k].t = broken[1699].t;    // repeated times
  broken[1800].t = 0.1;                                                       // backwards
  broken[1900].accel = Vec3(1e300, -1e300, 1e300);                            // absurd
  const AccelerometerTrack track(broken, o.R_cam_imu, 0.0, r.still, AccelerometerOptions{});
  ASSERT_FALSE(track.empty());
  for (double t0 = 0.0; t0 < 0.95; t0 += 0.05) {
    const MeasuredAcceleration m = track.window(t0, t0 + 0.05, t0);
    if (m.valid) {
      EXPECT_TRUE(m.a.allFinite()) << "t0=" << t0;
      EXPECT_TRUE(std::isfinite(m.sigma) && m.sigma > 0.0) << "t0=" << t0;
    }
  }
  // A window of NaN readings only has no answer; one that overlaps them is
  // answered from its other samples.
  EXPECT_FALSE(track.window(0.5, 0.6, 0.5).valid);
  const MeasuredAcceleration around = track.window(0.45, 0.64, 0.45);
  ASSERT_TRUE(around.valid);
  EXPECT_NEAR(around.t0, 0.45, 1.1e-3);  // the first sample at or after 0.45 (times carry rounding)
  EXPECT_NEAR(around.t1, 0.499, 1e-9);  // the samples of [0.5, 0.64) are NaN or infinite
  // Beyond that 0.15 s gap the integrated rotation is broken: no answer.
  EXPECT_FALSE(track.window(0.7, 0.8, 0.7).valid);
  EXPECT_FALSE(track.window(0.4, 0.8, 0.4).valid);
  // A recording of one usable sample has no track.
  std::vector<ImuSample> one(r.imu.begin(), r.imu.begin() + 1);
  EXPECT_TRUE(AccelerometerTrack(one, o.R_cam_imu, 0.0, r.still, AccelerometerOptions{}).empty());
}
