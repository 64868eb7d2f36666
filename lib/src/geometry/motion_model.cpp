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
                                        const std::vector<Vec3>& rates, double t_ref,
                                        VelocityFrame frame) {
  if (times.empty() || times.size() != rates.size())
    throw std::invalid_argument("gyroIntegrated: need equally many (>= 1) times and rates");
  for (size_t i = 1; i < times.size(); ++i)
    if (!(times[i] > times[i - 1]))
      throw std::invalid_argument("gyroIntegrated: sample times must increase");
  MotionModel m;
  m.kind_ = MotionModelKind::GyroIntegrated;
  m.frame_ = frame;
  m.t_ref_ = t_ref;
  m.times_ = times;
  m.rates_ = rates;
  if (times.size() > 1) m.samples_per_s_ = static_cast<double>(times.size() - 1) / (times.back() - times.front());
  // R_0_ti and Q_i = integral of R_0_s ds over [t_0, t_i], from the first
  // sample: each step turns at its mean rate w, so its rotation is exp(w dt)
  // and its integral R_0_ti J_l(w dt) dt.
  m.rotations_.resize(times.size());
  m.positions_.resize(times.size());
  m.rotations_[0] = Mat3::Identity();
  m.positions_[0] = Mat3::Zero();
  for (size_t i = 1; i < times.size(); ++i) {
    const double dt = times[i] - times[i - 1];
    Mat3 step_R, step_J;
    so3::expAndLeftJacobian(0.5 * (rates[i - 1] + rates[i]) * dt, step_R, step_J);
    m.positions_[i] = m.positions_[i - 1] + m.rotations_[i - 1] * step_J * dt;
    m.rotations_[i] = m.rotations_[i - 1] * step_R;
  }
  // Re-anchor so that R(t_ref) = I and P(t_ref) = 0.
  Mat3 R0_ref, Q_ref;
  m.samplePose(t_ref, R0_ref, &Q_ref);
  for (size_t i = 0; i < times.size(); ++i) {
    m.rotations_[i] = R0_ref.transpose() * m.rotations_[i];
    m.positions_[i] = R0_ref.transpose() * (m.positions_[i] - Q_ref);
  }
  return m;
}

inline Vec3 MotionModel::rateSlope(size_t i) const {
  return (rates_[i + 1] - rates_[i]) / (2.0 * (times_[i + 1] - times_[i]));
}

size_t MotionModel::pieceIndex(double t) const {
  if (kind_ == MotionModelKind::ConstantTwist || times_.size() == 1 || t <= times_.front()) return 0;
  if (!(t < times_.back())) return times_.size();  // also NaN, as upper_bound gives it
  // The first sample after t (upper_bound's answer, in 1..n-1): guessed
  // from the mean step, which a gyroscope's near-even clock makes right or
  // one off; searched where it is not.
  const size_t last = times_.size() - 1;
  size_t i = std::min(last, std::max<size_t>(1, static_cast<size_t>((t - times_.front()) * samples_per_s_) + 1));
  if (times_[i] <= t && i < last && times_[i + 1] > t) return i + 1;
  if (times_[i] > t && times_[i - 1] <= t) return i;
  if (times_[i] > t && i > 1 && times_[i - 2] <= t) return i - 1;
  return static_cast<size_t>(std::upper_bound(times_.begin(), times_.end(), t) - times_.begin());
}

MotionModel::RotationPiece MotionModel::piece(size_t index) const {
  RotationPiece p;
  if (kind_ == MotionModelKind::ConstantTwist || times_.empty()) return p;
  const size_t n = times_.size();
  const size_t i = index == 0 ? 0 : std::min(index, n) - 1;  // the sample the piece starts at
  p.t0 = times_[i], p.w0 = rates_[i], p.R0 = rotations_[i], p.P0 = positions_[i];
  if (index >= 1 && index < n) p.h = rateSlope(i);
  return p;
}

void MotionModel::sampleStep(double t, size_t& i, Vec3& phi, double& dt) const {
  const size_t index = pieceIndex(t), n = times_.size();
  i = index == 0 ? 0 : std::min(index, n) - 1;
  dt = t - times_[i];
  phi = (index >= 1 && index < n ? Vec3(rates_[i] + rateSlope(i) * dt) : rates_[i]) * dt;
}

void MotionModel::samplePose(double t, Mat3& R, Mat3* P) const {
  size_t i;
  Vec3 phi;
  double dt;
  sampleStep(t, i, phi, dt);
  if (!P) {
    R = rotations_[i] * so3::exp(phi);
    return;
  }
  Mat3 step_R, step_J;
  so3::expAndLeftJacobian(phi, step_R, step_J);
  *P = positions_[i] + rotations_[i] * step_J * dt;
  R = rotations_[i] * step_R;
}

Vec3 MotionModel::rotate(double t, const Vec3& x) const {
  // exp(phi) x = x + A phi x x + B phi x (phi x x).
  const auto act = [](const Vec3& phi, const Vec3& y) {
    double A, B, C;
    so3::coefficients(phi.squaredNorm(), A, B, C);
    const Vec3 py = phi.cross(y);
    return Vec3(y + A * py + B * phi.cross(py));
  };
  if (kind_ == MotionModelKind::ConstantTwist) return act(omega_ * (t - t_ref_), x);
  size_t i;
  Vec3 phi;
  double dt;
  sampleStep(t, i, phi, dt);
  return rotations_[i] * act(phi, x);
}

MotionModel::TransposedActions MotionModel::transposedActions(double t, const Vec3& a,
                                                              const Vec3& b) const {
  const double tau = t - t_ref_;
  TransposedActions out;
  // y - k1 phi x y + k2 phi x (phi x y).
  const auto act = [](const Vec3& phi, const Vec3& y, double k1, double k2) {
    const Vec3 py = phi.cross(y);
    return Vec3(y - k1 * py + k2 * phi.cross(py));
  };
  double A, B, C;
  if (kind_ == MotionModelKind::ConstantTwist) {
    const Vec3 phi = omega_ * tau;
    so3::coefficients(phi.squaredNorm(), A, B, C);
    out.Rt_a = act(phi, a, A, B), out.Rt_b = act(phi, b, A, B);
    out.Pt_a = tau * act(phi, a, B, C), out.Pt_b = tau * act(phi, b, B, C);
    return out;
  }
  size_t i;
  Vec3 phi;
  double dt;
  sampleStep(t, i, phi, dt);
  so3::coefficients(phi.squaredNorm(), A, B, C);
  const Vec3 ai = rotations_[i].transpose() * a, bi = rotations_[i].transpose() * b;
  out.Rt_a = act(phi, ai, A, B), out.Rt_b = act(phi, bi, A, B);
  if (frame_ == VelocityFrame::Reference) {
    out.Pt_a = tau * a, out.Pt_b = tau * b;
  } else {
    // P = P_i + R_i J_l(phi) dt.
    out.Pt_a = positions_[i].transpose() * a + dt * act(phi, ai, B, C);
    out.Pt_b = positions_[i].transpose() * b + dt * act(phi, bi, B, C);
  }
  return out;
}

Mat3 MotionModel::rotation(double t) const {
  if (kind_ == MotionModelKind::ConstantTwist) return so3::exp(omega_ * (t - t_ref_));
  Mat3 R;
  samplePose(t, R, nullptr);
  return R;
}

Mat3 MotionModel::positionMatrix(double t) const {
  const double tau = t - t_ref_;
  if (kind_ == MotionModelKind::ConstantTwist) return so3::leftJacobian(omega_ * tau) * tau;
  if (frame_ == VelocityFrame::Reference) return Mat3::Identity() * tau;
  Mat3 R, P;
  samplePose(t, R, &P);
  return P;
}

void MotionModel::pose(double t, Mat3& R, Mat3& P) const {
  const double tau = t - t_ref_;
  if (kind_ == MotionModelKind::ConstantTwist) {
    so3::expAndLeftJacobian(omega_ * tau, R, P);
    P *= tau;
    return;
  }
  if (frame_ == VelocityFrame::Reference) {
    samplePose(t, R, nullptr);
    P = Mat3::Identity() * tau;
    return;
  }
  samplePose(t, R, &P);
}

Vec3 MotionModel::meanOmega(double t0, double t1) const {
  if (kind_ == MotionModelKind::ConstantTwist || t1 <= t0) return omega_;
  return so3::log(rotation(t0).transpose() * rotation(t1)) / (t1 - t0);
}

MotionModel MotionModel::withOmegaOffset(const Vec3& delta) const {
  return withRateTransform(Mat3::Identity(), delta);
}

MotionModel MotionModel::withRateTransform(const Mat3& A, const Vec3& delta) const {
  if (kind_ == MotionModelKind::ConstantTwist) return constantTwist(A * omega_ + delta, t_ref_);
  std::vector<Vec3> rates = rates_;
  for (auto& r : rates) r = A * r + delta;
  return gyroIntegrated(times_, rates, t_ref_, frame_);
}

}  // namespace celc
