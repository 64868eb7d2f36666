#include "celc/geometry/motion_model.hpp"

#include <algorithm>
#include <stdexcept>

#include "celc/geometry/so3.hpp"

namespace celc {

MotionModelKind parseMotionModelKind(const std::string& name) {
  if (name == "constant_twist") return MotionModelKind::ConstantTwist;
  if (name == "gyro_integrated") return MotionModelKind::GyroIntegrated;
  throw std::invalid_argument("unknown motion model '" + name +
                              "' (expected constant_twist or gyro_integrated)");
}

std::string toString(MotionModelKind kind) {
  return kind == MotionModelKind::ConstantTwist ? "constant_twist" : "gyro_integrated";
}

MotionModel MotionModel::constantTwist(const Vec3& omega, double t_ref) {
  MotionModel m;
  m.kind_ = MotionModelKind::ConstantTwist;
  m.omega_ = omega;
  m.t_ref_ = t_ref;
  return m;
}

MotionModel MotionModel::gyroIntegrated(const std::vector<double>& times,
                                        const std::vector<Vec3>& rates, double t_ref) {
  if (times.empty() || times.size() != rates.size())
    throw std::invalid_argument("gyroIntegrated: need equally many (>= 1) times and rates");
  for (size_t i = 1; i < times.size(); ++i)
    if (!(times[i] > times[i - 1]))
      throw std::invalid_argument("gyroIntegrated: sample times must increase");
  MotionModel m;
  m.kind_ = MotionModelKind::GyroIntegrated;
  m.t_ref_ = t_ref;
  m.times_ = times;
  m.rates_ = rates;
  // R_0_ti from the first sample, trapezoidal (mean-rate) steps.
  m.rotations_.resize(times.size());
  m.rotations_[0] = Mat3::Identity();
  for (size_t i = 1; i < times.size(); ++i) {
    const double dt = times[i] - times[i - 1];
    m.rotations_[i] = m.rotations_[i - 1] * so3::exp(0.5 * (rates[i - 1] + rates[i]) * dt);
  }
  // Re-anchor so that R(t_ref) = I.
  const Mat3 R0_ref = m.rotation(t_ref);
  for (auto& R : m.rotations_) R = R0_ref.transpose() * R;
  return m;
}

Mat3 MotionModel::rotation(double t) const {
  if (kind_ == MotionModelKind::ConstantTwist) return so3::exp(omega_ * (t - t_ref_));
  // Interval [t_i, t_i+1] holding t (clamped at the ends, holding the end rate).
  if (times_.size() == 1 || t <= times_.front())
    return rotations_.front() * so3::exp(rates_.front() * (t - times_.front()));
  if (t >= times_.back()) return rotations_.back() * so3::exp(rates_.back() * (t - times_.back()));
  const size_t i = static_cast<size_t>(std::upper_bound(times_.begin(), times_.end(), t) -
                                       times_.begin()) - 1;
  const double dt = t - times_[i];
  const double s = dt / (times_[i + 1] - times_[i]);
  const Vec3 rate_t = (1.0 - s) * rates_[i] + s * rates_[i + 1];
  return rotations_[i] * so3::exp(0.5 * (rates_[i] + rate_t) * dt);
}

Mat3 MotionModel::positionMatrix(double t) const {
  const double tau = t - t_ref_;
  if (kind_ == MotionModelKind::ConstantTwist) return so3::leftJacobian(omega_ * tau) * tau;
  return Mat3::Identity() * tau;
}

void MotionModel::pose(double t, Mat3& R, Mat3& P) const {
  const double tau = t - t_ref_;
  if (kind_ == MotionModelKind::ConstantTwist) {
    so3::expAndLeftJacobian(omega_ * tau, R, P);
    P *= tau;
    return;
  }
  R = rotation(t);
  P = Mat3::Identity() * tau;
}

Vec3 MotionModel::meanOmega(double t0, double t1) const {
  if (kind_ == MotionModelKind::ConstantTwist || t1 <= t0) return omega_;
  return so3::log(rotation(t0).transpose() * rotation(t1)) / (t1 - t0);
}

MotionModel MotionModel::withOmegaOffset(const Vec3& delta) const {
  if (kind_ == MotionModelKind::ConstantTwist) return constantTwist(omega_ + delta, t_ref_);
  std::vector<Vec3> rates = rates_;
  for (auto& r : rates) r += delta;
  return gyroIntegrated(times_, rates, t_ref_);
}

}  // namespace celc
