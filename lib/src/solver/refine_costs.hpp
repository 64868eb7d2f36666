#pragma once
// Internal: Ceres costs of the refinement, one residual per event, evaluated in
// chunks (one residual block per chunk of a cluster's events) to keep Ceres'
// per-block overhead small.
//
// The event residual d is celc_residual.hpp's (pixels). Huber robustification
// inside the residual: r = sign(d) sqrt(rho(d^2)) with rho(x) = x for
// x <= delta^2, 2 delta sqrt(x) - delta^2 otherwise, so that
// sum r^2 = sum rho(d^2) exactly (the "square-rooted" Huber cost).
#include <ceres/ceres.h>

#include <vector>

#include "celc/solver/celc_residual.hpp"

namespace celc::detail {

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

/// Cauchy in square-root form: r = sign(d) c sqrt(log(1 + d^2 / c^2)), so that
/// sum r^2 = sum c^2 log(1 + d^2 / c^2); returns r and dr/dd.
inline double sqrtCauchy(double d, double c, double* slope) {
  const double q2 = (d / c) * (d / c);
  if (q2 < 1e-12) {
    *slope = 1.0;
    return d;
  }
  const double r = c * std::sqrt(std::log1p(q2));
  *slope = std::abs(d) / (r * (1.0 + q2));
  return d < 0 ? -r : r;
}

/// Tukey's biweight in the same square-root form: rho(d^2) = (c^2 / 3)
/// (1 - (1 - d^2 / c^2)^3) for |d| < c (about d^2 near 0) and c^2 / 3
/// beyond, where the slope is 0: such an event does not pull at all.
inline double sqrtTukey(double d, double c, double* slope) {
  const double q2 = (d / c) * (d / c);
  if (q2 < 1e-12) {
    *slope = 1.0;
    return d;
  }
  if (q2 >= 1.0) {
    *slope = 0.0;
    return d < 0 ? -c / std::sqrt(3.0) : c / std::sqrt(3.0);
  }
  const double u = 1.0 - q2;
  const double r = c * std::sqrt((1.0 - u * u * u) / 3.0);
  *slope = std::abs(d) * u * u / r;
  return d < 0 ? -r : r;
}

/// A chunk of one cluster's events: `count` terms from `first`, which must
/// outlive the cost (they are not copied). Parameters: v (3), and with joint
/// lines also m1 (3), m3 (3) of the cluster.
class EventChunkCost final : public ceres::CostFunction {
 public:
  EventChunkCost(const EventTerm* first, size_t count, double focal, double huber_px, bool joint)
      : terms_(first), count_(count), focal_(focal), huber_(huber_px), joint_(joint) {
    set_num_residuals(static_cast<int>(count_));
    mutable_parameter_block_sizes()->push_back(3);
    if (joint_) {
      mutable_parameter_block_sizes()->push_back(3);
      mutable_parameter_block_sizes()->push_back(3);
    }
  }

  /// The loss from here on: Cauchy with scale c [px] instead of Huber.
  void setCauchy(double c) { cauchy_ = c; }
  /// ... or Tukey's biweight with threshold c [px].
  void setTukey(double c) { tukey_ = c; }

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
    for (size_t i = 0; i < count_; ++i) {
      Vec3 gv, g1, g3;
      const double d = eventDistance(terms_[i], v, m1, m3, focal_, want ? &gv : nullptr,
                                     want && joint_ ? &g1 : nullptr, want && joint_ ? &g3 : nullptr);
      if (!std::isfinite(d)) return false;
      double slope = 1.0;
      residuals[i] = tukey_ > 0.0    ? sqrtTukey(d, tukey_, &slope)
                     : cauchy_ > 0.0 ? sqrtCauchy(d, cauchy_, &slope)
                                     : sqrtHuber(d, huber_, &slope);
      if (!want) continue;
      const Vec3* grads[3] = {&gv, &g1, &g3};
      for (int b = 0; b < (joint_ ? 3 : 1); ++b)
        if (jac[b])
          for (int k = 0; k < 3; ++k) jac[b][i * 3 + k] = slope * (*grads[b])(k);
    }
    return true;
  }

 private:
  const EventTerm* terms_;
  size_t count_;
  double focal_, huber_;
  double cauchy_ = 0.0;  // > 0: the Cauchy loss replaces Huber
  double tukey_ = 0.0;   // > 0: Tukey's biweight replaces both
  bool joint_;
  Vec3 m1_ = Vec3::Zero(), m3_ = Vec3::Zero();
};

}  // namespace celc::detail
