#pragma once
/// \file imu_still.hpp
/// The first still second of a recording's IMU stream and its mean gyro rate,
/// an estimate of the constant gyro bias (motion.gyro_bias) when the camera
/// rests there.
///
/// "Still": a span of `span_s` seconds where
///  (a) the gyro rates have a standard deviation of at most `max_gyro_std`
///      [rad/s] on every axis: a resting camera shows only sensor noise
///      (DAVIS IMUs: ~0.003 rad/s per axis at 1 kHz); a hand-held or moving
///      one varies by 0.05 rad/s and more;
///  (b) the accelerometer direction does not turn: the angle between the
///      mean accelerometer directions of the span's first and last fifths,
///      scaled to the whole span, is at most `max_accel_turn` [rad]. A camera
///      turning at a constant rate w shows a steady gyro (low variance) but
///      turns gravity in its frame by |w| sin(angle of w to gravity) per
///      second (0.95 rad/s: 0.95 rad in a second); a bias is not seen by the
///      accelerometer at all. Means over fifths (~200 samples at 1 kHz) keep
///      the accelerometer's sample noise (~0.01 rad) out of the measure.
///      And the accelerometer norm varies by at most `max_accel_rel_std`
///      times its mean (a camera shaken or carried);
///  (c) the mean rate is plausible as a bias: its norm is at most
///      `max_mean_rate` [rad/s] (kMaxStillBias: DAVIS gyros may start 20 deg/s
///      off).
/// A rotation about the gravity direction below max_mean_rate leaves (a) and
/// (b) unchanged: no IMU-only test tells it from a bias.
///
/// Without an accelerometer (every sample's accel exactly zero) (b) is
/// skipped, and the result carries a warning that says so.
///
/// Candidate spans start at the first sample and every step_s after it; the
/// first still one is reported. When there is none, `refused` says why the
/// first candidate (the recording's first second) is not still.
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc {

/// The largest gyro bias taken from a still span [rad/s] (norm of the mean):
/// the initial zero-rate offset of the InvenSense MPU-6x50 gyros in DAVIS
/// cameras may reach 20 deg/s (0.35 rad/s) per axis; a span whose mean rate
/// is larger is a camera turning at a constant rate, not one at rest.
inline constexpr double kMaxStillBias = 0.35;

struct StillOptions {
  double span_s = 1.0;                  ///< [s] length of the span
  double step_s = 0.25;                 ///< [s] between candidate starts
  double max_gyro_std = 0.02;           ///< [rad/s] per axis, (a)
  double max_accel_turn = 0.01;         ///< [rad] turn of the accelerometer direction over the span, (b)
  double max_accel_rel_std = 0.02;      ///< [-] std / mean of |accel|, (b)
  double max_mean_rate = kMaxStillBias; ///< [rad/s] norm of the mean gyro rate, (c)
  int min_samples = 20;                 ///< a span needs this many samples
  std::string validate() const;         ///< "" when usable, else what is wrong
};
/// StillOptions' fields with their units and ranges (core/fields.hpp);
/// validate() is their range check.
void describe(FieldVisitor& v, StillOptions& options);

struct StillSpan {
  bool found = false;
  double t0 = 0.0, t1 = 0.0;        ///< [s] the span
  int samples = 0;
  Vec3 gyro_mean = Vec3::Zero();    ///< [rad/s], IMU frame: the bias estimate
  Vec3 gyro_std = Vec3::Zero();     ///< [rad/s] per axis
  double accel_turn = 0.0;          ///< [rad] over the span (0 without accelerometer)
  Vec3 accel_mean = Vec3::Zero();   ///< [m/s^2], IMU frame: minus gravity, plus the accelerometer's bias
  Vec3 accel_std = Vec3::Zero();    ///< [m/s^2] per axis, the sample noise
  /// False when every accelerometer sample is zero: (b) was not tested.
  bool has_accel = true;
  /// Non-empty when the answer is weaker than usual (no accelerometer).
  std::string warning;
  /// Without a still span: why the first candidate span is not still, e.g.
  /// "the first span [0.000, 1.000] s: the accelerometer direction turns
  /// 0.950 rad in 1 s (more than 0.01 rad): the camera turns".
  std::string refused;

  /// The mean rate stands out of the noise: on some axis |mean| is at least
  /// `z` times std / sqrt(samples) (its standard error), and the norm of the
  /// mean is at least `min_rate` [rad/s]. False when not found.
  bool significant(double z, double min_rate) const;
};

/// The first still span of `imu` (time-ordered samples); found false when none.
StillSpan findFirstStill(const std::vector<ImuSample>& imu, const StillOptions& options = {});

}  // namespace celc
