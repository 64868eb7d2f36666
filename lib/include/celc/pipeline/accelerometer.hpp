#pragma once
/// \file accelerometer.hpp
/// The accelerometer as the camera's acceleration over a window, for
/// celc_acc's check (docs/method.md, "celc_acc").
///
/// The accelerometer measures the specific force in the IMU frame,
///   f = R_cam_imu^T (a_cam - g_cam) + b_a + n_a,
/// a_cam the camera's acceleration and g_cam gravity, both in the camera
/// frame at the sample's time (the IMU taken at the camera centre: no lever
/// arm). Gravity comes from a still span (imu_still.hpp), where a_cam = 0:
/// g_s = -R_cam_imu mean(f) in the camera frame at the span's middle time
/// t_s (the bias b_a goes into it). The gyro (bias removed), integrated from
/// t_s with the trapezoidal rule, gives R_s(t): camera at t_s <- camera at t.
/// For a window with reference time t_ref, a world-fixed acceleration is, in
/// the reference frame (the camera at t_ref),
///   a_ref = R_s(t_ref)^T ( mean_k R_s(t_k) R_cam_imu f_k + g_s ),
/// the mean over the window's samples t_k (camera time: t_imu + time_offset).
/// Its 1-sigma error per axis, sigma^2 = 2 bias^2 + noise^2 / n + (|g| e |t_ref - t_s|)^2:
/// the bias twice (in g_s and in the window; it cancels for a camera that
/// has not turned since the still span, and the sum bounds it for one that
/// has), the sample noise (the still span's std) over the n samples, and
/// gravity turned by the gyro's residual bias e (the still span's standard
/// error of its mean rate) over the time since the span.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/observations.hpp"
#include "celc/core/types.hpp"
#include "celc/pipeline/imu_still.hpp"

namespace celc {

struct AccelerometerOptions {
  /// Give celc_acc the accelerometer's acceleration where the IMU has an
  /// accelerometer and a still span (for gravity).
  bool use = true;
  /// [m/s^2] 1-sigma of the accelerometer's bias per axis, what the still
  /// span leaves of it (MPU-6x50 datasheets: +-0.5 m/s^2 zero-g offset
  /// before calibration, a few hundredths of that after).
  double bias_m_s2 = 0.05;
  std::string validate() const;  ///< empty when valid
};
/// The schema of the options (core/fields.hpp), keys `use_accelerometer`
/// and `accel_bias_m_s2` of the run configuration's `motion:` section.
void describe(FieldVisitor& v, AccelerometerOptions& options);

/// The accelerometer of a recording with gravity known from a still span.
class AccelerometerTrack {
 public:
  AccelerometerTrack() = default;
  /// `imu`: samples in time order with the gyro bias already removed (IMU
  /// frame); samples with a non-finite field or a time not after the last
  /// kept one are skipped. `still`: a found still span of the same samples
  /// (before the bias came off: its gyro_std and samples give the residual
  /// bias). `max_gap` [s]: a longer step between kept samples breaks the
  /// integrated rotation, and no window beyond it from the still span is answered.
  AccelerometerTrack(const std::vector<ImuSample>& imu, const Mat3& R_cam_imu, double time_offset,
                     const StillSpan& still, const AccelerometerOptions& options, double max_gap = 0.02);
  bool empty() const { return t_.empty(); }
  /// Gravity in the camera frame at the still span's middle [m/s^2].
  const Vec3& gravity() const { return g_s_; }
  /// a_ref over [t0, t1) for the reference time t_ref [s]; not valid where
  /// the track is empty, the window holds fewer than 2 samples, t_ref lies
  /// outside the samples, or a gap lies between the still span and them.
  MeasuredAcceleration window(double t0, double t1, double t_ref) const;

 private:
  /// R_s(t) at a time inside the samples: the sample before t, turned on at its rate.
  Mat3 rotationAt(double t) const;

  std::vector<double> t_;    ///< camera time [s]
  std::vector<Vec3> f_s_;    ///< R_s(t_k) R_cam_imu f_k [m/s^2]
  std::vector<Eigen::Quaterniond> R_s_;  ///< R_s(t_k)
  std::vector<Vec3> w_;      ///< camera-frame rate [rad/s]
  std::vector<int> gaps_;    ///< gaps longer than max_gap among the steps up to each sample
  std::size_t mid_ = 0;      ///< the sample at t_s
  Vec3 g_s_ = Vec3::Zero();  ///< gravity, camera frame at t_s [m/s^2]
  double t_s_ = 0.0;         ///< the still span's middle, camera time [s]
  double noise_ = 0.0;       ///< per-sample std [m/s^2], the still span's largest axis
  double rate_error_ = 0.0;  ///< e [rad/s]
  double bias_ = 0.0;        ///< [m/s^2]
};

}  // namespace celc
