#include "celc/eval/gt_velocity.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace celc {

std::string GtVelocityOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (min_poses < degree + 1)
    e += "min_poses: must be > degree (" + std::to_string(degree) + "), got " + std::to_string(min_poses) + "; ";
  return e;
}

std::string toString(GtStatus s) {
  switch (s) {
    case GtStatus::Ok: return "ok";
    case GtStatus::NotCovered: return "gt_not_covered";
    case GtStatus::TooFewPoses: return "gt_too_few_poses";
    case GtStatus::InvalidWindow: return "invalid_window";
  }
  return "gt_not_covered";
}

GtVelocityEstimator::GtVelocityEstimator(std::vector<PoseSample> poses, const Eigen::Matrix4d& T_body_cam,
                                         const GtVelocityOptions& options)
    : poses_(std::move(poses)), o_(options) {
  const std::string err = o_.validate();
  if (!err.empty()) throw std::invalid_argument("ground-truth velocity options: " + err);
  R_bc_ = T_body_cam.topLeftCorner<3, 3>();
  const Vec3 t_bc = T_body_cam.topRightCorner<3, 1>();
  p_cam_.reserve(poses_.size());
  for (const auto& p : poses_) p_cam_.push_back(p.position + p.orientation.toRotationMatrix() * t_bc);
}

GtVelocity GtVelocityEstimator::at(double t) const {
  GtVelocity r;
  if (!std::isfinite(t)) {
    r.status = GtStatus::InvalidWindow;
    return r;
  }
  if (poses_.size() < 2 || t < poses_.front().t || t > poses_.back().t) {
    r.status = GtStatus::NotCovered;
    return r;
  }
  auto lo = std::lower_bound(poses_.begin(), poses_.end(), t - o_.half_width,
                             [](const PoseSample& p, double v) { return p.t < v; });
  auto hi = std::upper_bound(poses_.begin(), poses_.end(), t + o_.half_width,
                             [](double v, const PoseSample& p) { return v < p.t; });
  const std::size_t i0 = std::size_t(lo - poses_.begin()), i1 = std::size_t(hi - poses_.begin());
  const int n = int(i1 - i0);
  if (n < o_.min_poses) {
    r.status = GtStatus::TooFewPoses;
    return r;
  }
  // weighted least squares in the scaled variable s = tau / half_width (conditioning)
  const int m = o_.degree + 1;
  Eigen::MatrixXd A(n, m);
  Eigen::MatrixXd B(n, 3);
  for (int k = 0; k < n; ++k) {
    const double s = (poses_[i0 + std::size_t(k)].t - t) / o_.half_width;
    double pw = 1.0;
    for (int j = 0; j < m; ++j, pw *= s) A(k, j) = pw;
    B.row(k) = p_cam_[i0 + std::size_t(k)].transpose();
  }
  const Eigen::MatrixXd C = A.colPivHouseholderQr().solve(B);
  if (!C.allFinite()) {
    r.status = GtStatus::TooFewPoses;
    return r;
  }
  const Vec3 v_world = C.row(1).transpose() / o_.half_width;
  // orientation at t: slerp between bracketing poses
  auto it = std::upper_bound(poses_.begin(), poses_.end(), t, [](double v, const PoseSample& p) { return v < p.t; });
  Eigen::Quaterniond q;
  if (it == poses_.end()) q = poses_.back().orientation;
  else if (it == poses_.begin()) q = poses_.front().orientation;
  else {
    const auto& a = *(it - 1);
    const auto& b = *it;
    q = a.orientation.slerp((t - a.t) / (b.t - a.t), b.orientation);
  }
  const Mat3 R_wc = q.toRotationMatrix() * R_bc_;
  r.v_cam = R_wc.transpose() * v_world;
  r.status = GtStatus::Ok;
  return r;
}

GtVelocity GtVelocityEstimator::window(double t0, double t1) const {
  GtVelocity r;
  if (!std::isfinite(t0) || !std::isfinite(t1) || !(t1 > t0)) {
    r.status = GtStatus::InvalidWindow;
    return r;
  }
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < o_.samples; ++i) {
    const double t = t0 + (t1 - t0) * (double(i) + 0.5) / double(o_.samples);
    const GtVelocity v = at(t);
    if (!v.ok()) return v;
    sum += v.v_cam;
  }
  r.v_cam = sum / double(o_.samples);
  r.status = GtStatus::Ok;
  return r;
}

}  // namespace celc
