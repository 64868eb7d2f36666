#pragma once
/// \file imu_still.hpp
/// The first still second of a recording's IMU stream and its mean gyro rate,
/// an estimate of the constant gyro bias (motion.gyro_bias) when the camera
/// rests there.
///
/// "Still": a span of `span_s` seconds whose gyro rates have a standard
/// deviation of at most `max_gyro_std` [rad/s] on every axis and whose
/// accelerometer norm has a standard deviation of at most `max_accel_rel_std`
/// times its mean (unit-free: m/s^2 and g alike). A resting camera shows only
/// sensor noise (DAVIS IMUs: ~0.003 rad/s per axis at 1 kHz); hand-held or
/// moving, the rates vary by 0.05 rad/s and more. Candidate spans start at the
/// first sample and every step_s after it; the first still one is reported.
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

struct StillOptions {
  double span_s = 1.0;              ///< [s] length of the span
  double step_s = 0.25;             ///< [s] between candidate starts
  double max_gyro_std = 0.02;       ///< [rad/s] per axis
  double max_accel_rel_std = 0.02;  ///< [-] std / mean of |accel|
  int min_samples = 20;             ///< a span needs this many samples
};

struct StillSpan {
  bool found = false;
  double t0 = 0.0, t1 = 0.0;        ///< [s] the span
  int samples = 0;
  Vec3 gyro_mean = Vec3::Zero();    ///< [rad/s], IMU frame: the bias estimate
  Vec3 gyro_std = Vec3::Zero();     ///< [rad/s] per axis
};

/// The first still span of `imu` (time-ordered samples); found false when none.
StillSpan findFirstStill(const std::vector<ImuSample>& imu, const StillOptions& options = {});

}  // namespace celc
