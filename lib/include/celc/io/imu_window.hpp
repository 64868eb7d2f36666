#pragma once
/// \file imu_window.hpp
/// The gyroscope over a window, in the camera frame and camera time:
///   w_cam(t) = R_cam_imu * gyro(t_imu),  t = t_imu + time_offset,
/// linearly interpolated between samples. For [t0, t1) it gives the mean
///   w_mean = 1/(t1 - t0) * integral_{t0}^{t1} w_cam(t) dt
/// (exact for the piecewise-linear signal) and the samples (with interpolated
/// end points at t0 and t1) for MotionModel::gyroIntegrated. A window the
/// samples do not cover, or with a gap longer than max_gap, gets a status.
#include <string>
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc {

enum class GyroStatus { Ok, NoSamples, NotCovered, Gap, InvalidWindow };
std::string toString(GyroStatus status);  ///< "ok", "no_gyro", "not_covered", "gyro_gap", "invalid_window"

struct GyroWindowOptions {
  /// Largest allowed spacing between consecutive samples inside the window, and
  /// the largest distance the window ends may lie outside the sampled range [s].
  double max_gap = 0.02;
  std::string validate() const;
};
/// The schema of the gyroscope window checks (core/fields.hpp).
void describe(FieldVisitor& v, GyroWindowOptions& options);


struct GyroWindow {
  GyroStatus status = GyroStatus::NoSamples;
  Vec3 mean_omega = Vec3::Zero();  ///< [rad/s], camera frame
  std::vector<double> times;       ///< t0, samples inside (t0, t1), t1 [s]
  std::vector<Vec3> rates;         ///< [rad/s], camera frame
  bool ok() const { return status == GyroStatus::Ok; }
  /// MotionModel::gyroIntegrated over these samples (requires ok()).
  MotionModel motionModel(double t_ref) const { return MotionModel::gyroIntegrated(times, rates, t_ref); }
};

/// The gyroscope signal of a recording, rotated into the camera frame.
class GyroTrack {
 public:
  GyroTrack() = default;
  /// Samples must be in time order (IMU readers return them so; out-of-order ones are dropped).
  GyroTrack(const std::vector<ImuSample>& imu, const Mat3& R_cam_imu, double time_offset,
            const GyroWindowOptions& options = {});
  std::size_t size() const { return t_.size(); }
  bool empty() const { return t_.empty(); }
  double tFirst() const { return t_.front(); }
  double tLast() const { return t_.back(); }
  /// Interpolated rate at t [rad/s] (ends held outside the range); requires !empty().
  Vec3 rateAt(double t) const;
  /// The window [t0, t1).
  GyroWindow window(double t0, double t1) const;

 private:
  std::vector<double> t_;
  std::vector<Vec3> w_;
  GyroWindowOptions options_;
};

}  // namespace celc
