// The accelerometer over a window (accelerometer.hpp).
#include "celc/pipeline/accelerometer.hpp"

#include <algorithm>
#include <cmath>

#include "celc/geometry/so3.hpp"

namespace celc {

void describe(FieldVisitor& v, AccelerometerOptions& o) {
  v.field({"use_accelerometer", "",
           "give celc_acc the accelerometer's acceleration (needs a still span for gravity)"},
          o.use);
  v.field({"accel_bias_m_s2", "m/s^2", "1-sigma accelerometer bias per axis left after the still span",
           within(0, 10)},
          o.bias_m_s2);
}

std::string AccelerometerOptions::validate() const { return rangeProblemsOf(*this); }

AccelerometerTrack::AccelerometerTrack(const std::vector<ImuSample>& imu, const Mat3& R_cam_imu, double time_offset,
                                       const StillSpan& still, const AccelerometerOptions& options, double max_gap) {
  if (!still.found || !still.has_accel || imu.size() < 2) return;
  std::vector<ImuSample> kept;
  kept.reserve(imu.size());
  for (const ImuSample& s : imu)
    if (std::isfinite(s.t) && s.gyro.allFinite() && s.accel.allFinite() && (kept.empty() || s.t > kept.back().t))
      kept.push_back(s);
  if (kept.size() < 2) return;
  const std::size_t n = kept.size();
  t_.resize(n);
  w_.resize(n);
  gaps_.assign(n, 0);
  R_s_.resize(n);
  f_s_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    t_[k] = kept[k].t + time_offset;
    w_[k] = R_cam_imu * kept[k].gyro;
    if (k > 0) gaps_[k] = gaps_[k - 1] + (t_[k] - t_[k - 1] > max_gap ? 1 : 0);
  }
  t_s_ = 0.5 * (still.t0 + still.t1) + time_offset;
  const std::size_t mid = static_cast<std::size_t>(
      std::min<std::ptrdiff_t>(std::lower_bound(t_.begin(), t_.end(), t_s_) - t_.begin(), n - 1));
  t_s_ = t_[mid];
  mid_ = mid;
  // Unit quaternions, renormalised at every step (a long recording's product drifts off unit norm).
  const auto step = [&](std::size_t a, std::size_t b) {
    return Eigen::Quaterniond(so3::exp(0.5 * (w_[a] + w_[b]) * (t_[b] - t_[a])));
  };
  R_s_[mid] = Eigen::Quaterniond::Identity();
  for (std::size_t k = mid + 1; k < n; ++k) R_s_[k] = (R_s_[k - 1] * step(k - 1, k)).normalized();
  for (std::size_t k = mid; k-- > 0;) R_s_[k] = (R_s_[k + 1] * step(k, k + 1).conjugate()).normalized();
  for (std::size_t k = 0; k < n; ++k) f_s_[k] = R_s_[k] * (R_cam_imu * kept[k].accel);
  g_s_ = -(R_cam_imu * still.accel_mean);
  noise_ = still.accel_std.maxCoeff();
  rate_error_ = still.samples > 0 ? still.gyro_std.maxCoeff() / std::sqrt(static_cast<double>(still.samples)) : 0.0;
  bias_ = options.bias_m_s2;
}

Mat3 AccelerometerTrack::rotationAt(double t) const {
  const auto it = std::upper_bound(t_.begin(), t_.end(), t);
  const std::size_t k = it == t_.begin() ? 0 : static_cast<std::size_t>(it - t_.begin()) - 1;
  return R_s_[k].toRotationMatrix() * so3::exp(w_[k] * (t - t_[k]));
}

MeasuredAcceleration AccelerometerTrack::window(double t0, double t1, double t_ref) const {
  MeasuredAcceleration out;
  if (t_.empty() || !(t1 > t0) || !(t_ref >= t_.front() && t_ref <= t_.back())) return out;
  const auto begin = std::lower_bound(t_.begin(), t_.end(), t0);
  const auto end = std::lower_bound(t_.begin(), t_.end(), t1);
  const std::ptrdiff_t count = end - begin;
  if (count < 2) return out;
  // No gap between the still span and the window's samples or t_ref.
  const auto ref = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t_ref) - t_.begin()) - 1;
  const std::size_t lo = std::min({mid_, static_cast<std::size_t>(begin - t_.begin()), ref});
  const std::size_t hi = std::max({mid_, static_cast<std::size_t>(end - t_.begin()) - 1, ref});
  if (gaps_[hi] != gaps_[lo]) return out;
  Vec3 sum = Vec3::Zero();
  for (auto k = static_cast<std::size_t>(begin - t_.begin()); k < static_cast<std::size_t>(end - t_.begin()); ++k)
    sum += f_s_[k];
  out.a = rotationAt(t_ref).transpose() * (sum / static_cast<double>(count) + g_s_);
  out.t0 = *begin;
  out.t1 = *(end - 1);
  const double drift = g_s_.norm() * rate_error_ * std::abs(t_ref - t_s_);
  out.sigma = std::sqrt(2.0 * bias_ * bias_ + noise_ * noise_ / static_cast<double>(count) + drift * drift);
  out.valid = out.a.allFinite() && std::isfinite(out.sigma);
  return out;
}

}  // namespace celc
