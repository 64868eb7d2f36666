#pragma once
// Internal: Ceres costs of the refinement, one residual per event, evaluated in
// chunks (one residual block per chunk of a cluster's events) to keep Ceres'
// per-block overhead small.
//
// The event residual d is celc_residual.hpp's (pixels), robustified inside
// the residual in the square-root form of the cost's loss (robust_loss.hpp:
// r = sign(d) sqrt(rho(d)), so that sum r^2 = sum rho exactly).
#include <ceres/ceres.h>

#include <vector>

#include "celc/solver/celc_residual.hpp"
#include "robust_loss.hpp"

namespace celc::detail {

/// A chunk of one cluster's events: `count` terms from `first`, which must
/// outlive the cost (they are not copied). Parameters: v (3), and with joint
/// lines also m1 (3), m3 (3) of the cluster.
class EventChunkCost final : public ceres::CostFunction {
 public:
  /// Under Huber's loss at huber_px [px] until setLoss().
  EventChunkCost(const EventTerm* first, size_t count, double focal, double huber_px, bool joint)
      : terms_(first), count_(count), focal_(focal), loss_(RobustLoss::huber(huber_px)), joint_(joint) {
    set_num_residuals(static_cast<int>(count_));
    mutable_parameter_block_sizes()->push_back(3);
    if (joint_) {
      mutable_parameter_block_sizes()->push_back(3);
      mutable_parameter_block_sizes()->push_back(3);
    }
  }

  /// The loss from here on (its scale in px).
  void setLoss(const RobustLoss& loss) { loss_ = loss; }

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
      residuals[i] = loss_.sqrtResidual(d, &slope);
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
  double focal_;
  RobustLoss loss_;
  bool joint_;
  Vec3 m1_ = Vec3::Zero(), m3_ = Vec3::Zero();
};

}  // namespace celc::detail
