#include "celc/io/imu_window.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace celc {

std::string toString(GyroStatus status) {
  switch (status) {
    case GyroStatus::Ok: return "ok";
    case GyroStatus::NoSamples: return "no_gyro";
    case GyroStatus::NotCovered: return "not_covered";
    case GyroStatus::Gap: return "gyro_gap";
    case GyroStatus::InvalidWindow: return "invalid_window";
  }
  return "no_gyro";
}

std::string GyroWindowOptions::validate() const { return rangeProblemsOf(*this); }

GyroTrack::GyroTrack(const std::vector<ImuSample>& imu, const Mat3& R_cam_imu, double time_offset,
                     const GyroWindowOptions& options)
    : options_(options) {
  const std::string err = options_.validate();
  if (!err.empty()) throw std::invalid_argument("gyro window options: " + err);
  t_.reserve(imu.size());
  w_.reserve(imu.size());
  for (const ImuSample& s : imu) {
    const double t = s.t + time_offset;
    if (!std::isfinite(t) || !s.gyro.allFinite()) continue;
    if (!t_.empty() && t <= t_.back()) continue;
    t_.push_back(t);
    w_.push_back(R_cam_imu * s.gyro);
  }
}

Vec3 GyroTrack::rateAt(double t) const {
  if (t <= t_.front()) return w_.front();
  if (t >= t_.back()) return w_.back();
  const std::size_t k = std::size_t(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
  const double a = (t - t_[k - 1]) / (t_[k] - t_[k - 1]);
  return (1.0 - a) * w_[k - 1] + a * w_[k];
}

GyroWindow GyroTrack::window(double t0, double t1) const {
  GyroWindow g;
  if (!std::isfinite(t0) || !std::isfinite(t1) || !(t1 > t0)) {
    g.status = GyroStatus::InvalidWindow;
    return g;
  }
  if (t_.empty()) {
    g.status = GyroStatus::NoSamples;
    return g;
  }
  if (t0 < t_.front() - options_.max_gap || t1 > t_.back() + options_.max_gap) {
    g.status = GyroStatus::NotCovered;
    return g;
  }
  g.times.push_back(t0);
  g.rates.push_back(rateAt(t0));
  auto it = std::upper_bound(t_.begin(), t_.end(), t0);
  for (; it != t_.end() && *it < t1; ++it) {
    const std::size_t k = std::size_t(it - t_.begin());
    g.times.push_back(t_[k]);
    g.rates.push_back(w_[k]);
  }
  g.times.push_back(t1);
  g.rates.push_back(rateAt(t1));
  // gaps: between the samples that bracket the window
  const std::size_t lo = std::size_t(std::max<std::ptrdiff_t>(
      0, std::upper_bound(t_.begin(), t_.end(), t0) - t_.begin() - 1));
  const std::size_t hi = std::min(t_.size() - 1, std::size_t(std::lower_bound(t_.begin(), t_.end(), t1) - t_.begin()));
  for (std::size_t k = lo; k < hi; ++k)
    if (t_[k + 1] - t_[k] > options_.max_gap) {
      g.status = GyroStatus::Gap;
      return g;
    }
  Vec3 integral = Vec3::Zero();
  for (std::size_t k = 0; k + 1 < g.times.size(); ++k)
    integral += 0.5 * (g.times[k + 1] - g.times[k]) * (g.rates[k] + g.rates[k + 1]);
  g.mean_omega = integral / (t1 - t0);
  g.status = GyroStatus::Ok;
  return g;
}

}  // namespace celc
