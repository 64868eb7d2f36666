#pragma once
// Internal: the Ceres cost of one event for the refinement of v alone.
#include <ceres/ceres.h>

#include "celc/types.hpp"

namespace celc::detail {

/// d(v) = focal * a^T v / |N v| with N the 2x3 normaliser: the event's
/// distance to its transferred line [px]. Analytic Jacobian:
///   dd/dv = focal * ( a / g - (a^T v) N^T N v / g^3 ),  g = |N v|.
class EventLineDistance final : public ceres::SizedCostFunction<1, 3> {
 public:
  EventLineDistance(const Vec3& a, const Eigen::Matrix<double, 2, 3>& N, double focal)
      : a_(a), N_(N), focal_(focal) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Vec3> v(parameters[0]);
    const Eigen::Vector2d g = N_ * v;
    const double gn = g.norm();
    if (!(gn > 1e-300)) return false;
    const double av = a_.dot(v);
    residuals[0] = focal_ * av / gn;
    if (jacobians && jacobians[0]) {
      const Vec3 J = focal_ * (a_ / gn - av * (N_.transpose() * g) / (gn * gn * gn));
      for (int i = 0; i < 3; ++i) jacobians[0][i] = J(i);
    }
    return true;
  }

 private:
  Vec3 a_;
  Eigen::Matrix<double, 2, 3> N_;
  double focal_;
};

}  // namespace celc::detail
