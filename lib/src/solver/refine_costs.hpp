#pragma once
// Internal: Ceres costs of the refinement, one residual per event, evaluated in
// chunks (one residual block per chunk of a cluster's events) to keep Ceres'
// per-block overhead small.
//
// Event residual (distance to the transferred line, pixels):
//   l = m1 (u.v) - m3 (s.v),  u = De^T m3,  s = Ds^T m1,   (reference frame)
//   g = Rt01 l  (first two components of the line in the camera at t_k),
//   d = focal * fp.l / |g|,   fp = R_k f_k.
// Huber robustification inside the residual: r = sign(d) sqrt(rho(d^2)) with
// rho(x) = x for x <= delta^2, 2 delta sqrt(x) - delta^2 otherwise, so that
// sum r^2 = sum rho(d^2) exactly (the "square-rooted" Huber cost).
#include <ceres/ceres.h>

#include <vector>

#include "celc/types.hpp"

namespace celc::detail {

/// Per-event constants of the residual.
struct EventTerm {
  Vec3 fp;                            // R_k f_k
  Eigen::Matrix<double, 2, 3> Rt01;   // first two rows of R_k^T
  Mat3 De, Ds;                        // P(t_e) - P(t_k), P(t_s) - P(t_k)
};

/// d and its gradients w.r.t. v, m1, m3 (any of the gradient pointers may be null).
inline double eventDistance(const EventTerm& e, const Vec3& v, const Vec3& m1, const Vec3& m3,
                            double focal, Vec3* dv, Vec3* dm1, Vec3* dm3) {
  const Vec3 u = e.De.transpose() * m3, s = e.Ds.transpose() * m1;
  const double uv = u.dot(v), sv = s.dot(v);
  const Vec3 l = m1 * uv - m3 * sv;
  const Eigen::Vector2d g = e.Rt01 * l;
  const double gn = g.norm();
  if (!(gn > 1e-300)) return NAN;
  const double num = e.fp.dot(l);
  const double d = focal * num / gn;
  if (dv || dm1 || dm3) {
    // dd/dl (as a column vector).
    const Vec3 dl = focal * (e.fp / gn - num * (e.Rt01.transpose() * g) / (gn * gn * gn));
    if (dv) *dv = (m1 * u.transpose() - m3 * s.transpose()).transpose() * dl;
    if (dm1) *dm1 = (uv * Mat3::Identity() - m3 * (e.Ds * v).transpose()).transpose() * dl;
    if (dm3) *dm3 = (m1 * (e.De * v).transpose() - sv * Mat3::Identity()).transpose() * dl;
  }
  return d;
}

/// Huber in square-root form: returns r = sign(d) sqrt(rho(d^2)) and dr/dd.
inline double sqrtHuber(double d, double delta, double* slope) {
  const double a = std::abs(d);
  if (a <= delta) {
    *slope = 1.0;
    return d;
  }
  const double rho = 2.0 * delta * a - delta * delta;
  const double r = std::sqrt(rho);
  *slope = delta / r;
  return d < 0 ? -r : r;
}

/// A chunk of one cluster's events. Parameters: v (3), and with joint lines
/// also m1 (3), m3 (3) of the cluster.
class EventChunkCost final : public ceres::CostFunction {
 public:
  EventChunkCost(std::vector<EventTerm> terms, double focal, double huber_px, bool joint)
      : terms_(std::move(terms)), focal_(focal), huber_(huber_px), joint_(joint) {
    set_num_residuals(static_cast<int>(terms_.size()));
    mutable_parameter_block_sizes()->push_back(3);
    if (joint_) {
      mutable_parameter_block_sizes()->push_back(3);
      mutable_parameter_block_sizes()->push_back(3);
    }
  }

  /// With joint == false, m1 and m3 are the cluster's fixed lines.
  void setFixedLines(const Vec3& m1, const Vec3& m3) {
    m1_ = m1;
    m3_ = m3;
  }

  bool Evaluate(double const* const* p, double* residuals, double** jac) const override {
    const Eigen::Map<const Vec3> v(p[0]);
    const Vec3 m1 = joint_ ? Vec3(Eigen::Map<const Vec3>(p[1])) : m1_;
    const Vec3 m3 = joint_ ? Vec3(Eigen::Map<const Vec3>(p[2])) : m3_;
    const bool want = jac != nullptr;
    for (size_t i = 0; i < terms_.size(); ++i) {
      Vec3 gv, g1, g3;
      const double d = eventDistance(terms_[i], v, m1, m3, focal_, want ? &gv : nullptr,
                                     want && joint_ ? &g1 : nullptr, want && joint_ ? &g3 : nullptr);
      if (!std::isfinite(d)) return false;
      double slope = 1.0;
      residuals[i] = sqrtHuber(d, huber_, &slope);
      if (!want) continue;
      const Vec3* grads[3] = {&gv, &g1, &g3};
      for (int b = 0; b < (joint_ ? 3 : 1); ++b)
        if (jac[b])
          for (int k = 0; k < 3; ++k) jac[b][i * 3 + k] = slope * (*grads[b])(k);
    }
    return true;
  }

 private:
  std::vector<EventTerm> terms_;
  double focal_, huber_;
  bool joint_;
  Vec3 m1_ = Vec3::Zero(), m3_ = Vec3::Zero();
};

}  // namespace celc::detail
