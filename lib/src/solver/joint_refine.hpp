#pragma once
// Internal: celc_ml's joint refinement of v and every cluster's lines
// (m1, m3), a Levenberg-Marquardt on the cost of refine_costs.hpp
// (sum of Huber rho(d^2) over the events, d the CELC event distance in px)
// with each cluster's lines eliminated per step (Schur complement): the
// normal equations have a 2x2 block for v (tangent of the unit sphere),
// a 4x4 block per cluster (the tangents of m1 and m3) and their coupling,
// so one step costs O(events) and a 2x2 solve. The same cost as the Ceres
// refinement (refine.hpp), without its per-problem set-up; or, after
// setLoss(Cauchy / Tukey), that cost by iteratively reweighted steps.
#include <cstdint>
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"
#include "celc/solver/celc_residual.hpp"
#include "constraint_rows.hpp"
#include "joint_kernel.hpp"
#include "sampling.hpp"

namespace celc::detail {

/// The joint problem of one window: the event terms of the usable clusters
/// (a seeded subset of max_events events, as refine.hpp draws it; 0 = all).
class JointProblem {
 public:
  JointProblem(const WindowObservations& obs, const MotionModel& motion, const WindowFrames& frames,
               int max_events, bool balance_clusters, std::uint64_t event_seed, double huber_px);
  ~JointProblem();
  JointProblem(const JointProblem&) = delete;
  JointProblem& operator=(const JointProblem&) = delete;

  /// A point of the problem: v and each cluster's plane normals (unit).
  struct State {
    Vec3 v;
    std::vector<Vec3> m1, m3;
  };
  /// v with the fitted lines of the frames.
  State start(const Vec3& v) const;
  /// Robust cost 1/2 sum rho(d^2) [px^2] over every stride-th event of each
  /// cluster; +inf when a distance is not finite.
  double cost(const State& s, int stride = 1) const;

  struct Result {
    State state;
    double cost = 0.0;  ///< at the end, over the events used
    int iterations = 0;
    int events = 0;     ///< events used
    bool ok = false;
    bool merged = false;  ///< stopped early at one of merge_into
  };
  /// Levenberg-Marquardt from s over every stride-th event, until the
  /// relative cost decrease is below function_tolerance or max_iterations,
  /// or (merged) until the state is within merge_rad [rad] of one of
  /// merge_into in v and in every line normal (sign-agnostic): from there
  /// it would follow that state's descent.
  Result refine(State s, int max_iterations, double function_tolerance, int stride = 1,
                const std::vector<State>& merge_into = {}, double merge_rad = 0.0) const;

  /// Events in the problem.
  size_t events() const;
  /// Clusters in the problem.
  size_t clusters() const { return begin_.size() - 1; }
  /// The spread of the residuals at s (sampling.hpp).
  ResidualSpread spread(const State& s) const;
  double robustScale(const State& s) const;  ///< spread(s).scale
  /// The loss of the cost: Huber with threshold scale [px] (sum of Huber
  /// rho(d^2)), or Cauchy with scale c [px], rho = c^2 log(1 + d^2 / c^2),
  /// a redescending loss: an event far from its cluster's line (another
  /// edge's) pulls ~c^2 / d instead of Huber's constant c; or Tukey's
  /// biweight with scale c [px], rho = c^2 / 3 (1 - (1 - d^2 / c^2)^3)
  /// within c and c^2 / 3 beyond: an event beyond c does not pull at all.
  /// Cauchy and Tukey are minimised by reweighted steps (weights frozen at
  /// the point of linearisation).
  enum class Loss { Huber, Cauchy, Tukey };
  void setLoss(Loss loss, double scale_px) {
    loss_ = loss;
    scale_ = scale_px;
  }
  void setHuber(double huber_px) { setLoss(Loss::Huber, huber_px); }
  double lossScale() const { return scale_; }  ///< the loss's threshold or scale [px]

 private:
  /// The terms of cluster c: terms_[begin_[c], begin_[c + 1]). The buffer's
  /// memory is kept per thread across problems: allocating and releasing it
  /// per window made the kernel map and unmap its pages every time, which
  /// cost more than building the terms.
  std::vector<EventTerm> terms_;
  std::vector<size_t> begin_{0};
  /// Every stride-th event of terms_ as columns, for the passes of
  /// joint_kernel.hpp, with the clusters' ranges in them; formed for the
  /// stride of the last pass that asked (columns()).
  mutable JointColumns columns_;
  mutable std::vector<size_t> column_begin_;
  mutable int column_stride_ = 0;
  const JointColumns& columns(int stride) const;
  mutable std::vector<double> distances_;  // cost()'s under a Cauchy loss, per event
  std::vector<Vec3> m1_, m3_;                  // fitted lines (frames), unit
  /// rho(d) (twice the event's cost) and the IRLS residual r with dr/dd.
  double rho(double d) const;
  double weighted(double d, double* slope) const;
  double focal_, scale_;
  Loss loss_ = Loss::Huber;
};

}  // namespace celc::detail
