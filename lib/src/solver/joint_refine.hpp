#pragma once
// Internal: celc_ml's joint refinement of v and every cluster's lines
// (m1, m3), a Levenberg-Marquardt on the cost of refine_costs.hpp
// (sum of Huber rho(d^2) over the events, d the CELC event distance in px)
// with each cluster's lines eliminated per step (Schur complement): the
// normal equations have a 2x2 block for v (tangent of the unit sphere),
// a 4x4 block per cluster (the tangents of m1 and m3) and their coupling,
// so one step costs O(events) and a 2x2 solve. The same cost as the Ceres
// refinement (refine.hpp), without its per-problem set-up; or, after
// setLoss() with Cauchy's or Tukey's loss, that cost by iteratively
// reweighted steps (robust_loss.hpp).
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
  /// With `acceleration`, the camera's position is P(t) v + q(t) a,
  /// q(t) = (t - t_ref)^2 / 2 (celc_acc.hpp): a reference-frame acceleration
  /// over the speed [1/s] joins v and the lines as unknowns.
  JointProblem(const WindowObservations& obs, const MotionModel& motion, const WindowFrames& frames,
               int max_events, bool balance_clusters, std::uint64_t event_seed, double huber_px,
               bool acceleration = false);
  ~JointProblem();
  JointProblem(const JointProblem&) = delete;
  JointProblem& operator=(const JointProblem&) = delete;

  /// A point of the problem: v and each cluster's plane normals (unit), and
  /// the acceleration a (zero, and left so, without one).
  struct State {
    Vec3 v;
    std::vector<Vec3> m1, m3;
    Vec3 a = Vec3::Zero();
  };
  /// v (and a) with the fitted lines of the frames.
  State start(const Vec3& v, const Vec3& a = Vec3::Zero()) const;
  bool hasAcceleration() const { return acceleration_; }
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
  /// Levenberg-Marquardt from s over every stride-th event (v, the lines,
  /// and a with an acceleration), until the
  /// relative cost decrease is below function_tolerance or max_iterations,
  /// or (merged) until the state is within merge_rad [rad] of one of
  /// merge_into in v and in every line normal (sign-agnostic): from there
  /// it would follow that state's descent.
  Result refine(State s, int max_iterations, double function_tolerance, int stride = 1,
                const std::vector<State>& merge_into = {}, double merge_rad = 0.0) const;

  /// refine() with a held at zero (a problem with an acceleration, refined
  /// under the constant-velocity model on the same events and loss).
  Result refineConstantVelocity(State s, int max_iterations, double function_tolerance, int stride = 1) const;

  /// The Gauss-Newton information of the global unknowns at s over every
  /// event, with every cluster's lines eliminated (Schur complement) [1/px^2
  /// per unit^2, the loss's weights at s]: 2 x 2 over v's tangent
  /// (tangentBasis(s.v)), with an acceleration 5 x 5, then a.
  Eigen::MatrixXd information(const State& s) const;

  /// The cluster-robust (sandwich) covariance of the global unknowns at s
  /// [unit^2, same order as information()]:
  ///   H^-1 (sum_k g_k g_k^T) H^-1 K / (K - G),
  /// H = information(s), g_k cluster k's gradient of the cost over the
  /// global unknowns with its lines eliminated (g_k - W_k U_k^-1 b_k), K
  /// clusters, G global unknowns. The events of one cluster share their
  /// errors (the renderer's or the sensor's edge, the clustering), so the
  /// clusters, not the events, are the independent samples; with
  /// independent events of noise s it tends to s^2 H^-1. NaN where H is
  /// singular or K <= G.
  Eigen::MatrixXd clusterRobustCovariance(const State& s) const;

  /// Per cluster, whether its events agree with the other clusters' at s (a
  /// minimum of the cost, no acceleration): with g_k its efficient score
  /// (its gradient over v's tangent, its lines at their own optimum), H_k
  /// its information with its lines eliminated and H the window's, leaving
  /// it out moves v by about (H - H_k)^-1 g_k, and
  ///   T_k = g_k^T (H_k^+ + (H - H_k)^-1) g_k / sigma^2
  /// is that move against its spread under the model (events of one edge
  /// with independent noise of sigma [px]): chi-square with rank(H_k) <= 2
  /// degrees of freedom. NaN for a cluster left out or where H - H_k is
  /// singular; empty with an acceleration.
  std::vector<double> clusterAgreement(const State& s, double sigma_px) const;
  /// The clusters (indices of this problem) whose events every later
  /// cost, step and spread leaves out; their lines stay where they are.
  void leaveOut(const std::vector<size_t>& clusters);
  /// Cluster c (an index of this problem) back in, after leaveOut.
  void takeBack(size_t c);
  /// The WindowObservations index of each cluster of this problem.
  const std::vector<int>& observationIndex() const { return obs_index_; }

  /// Events in the problem.
  size_t events() const;
  /// Clusters in the problem.
  size_t clusters() const { return begin_.size() - 1; }
  /// The spread of the residuals at s (sampling.hpp).
  ResidualSpread spread(const State& s) const;
  double robustScale(const State& s) const;  ///< spread(s).scale
  /// The loss of the cost (robust_loss.hpp; scale in px): Huber's at first
  /// (huber_px); Cauchy's, whose far events (another edge's) pull ~c^2 / d
  /// instead of Huber's constant c, or Tukey's, whose events beyond c do not
  /// pull at all, minimised by reweighted steps.
  void setLoss(const RobustLoss& loss) { loss_ = loss; }
  const RobustLoss& loss() const { return loss_; }

 private:
  /// Per cluster: the Gauss-Newton blocks at a state, the tangent bases of
  /// its lines, and (per try) U_d^-1 [W^T | bc] with U_d the damped U.
  template <int G>
  struct ClusterBlocks {
    Eigen::Matrix4d U;
    Eigen::Matrix<double, G, 4> W;
    Eigen::Vector4d bc;
    Eigen::Matrix<double, G, 1> bg;  ///< the cluster's part of the global gradient
    Eigen::Matrix<double, G, G> Vc;  ///< the cluster's part of the global block
    Eigen::Matrix<double, 3, 2> B1, B3;
    Eigen::Matrix<double, 4, G + 1> X;
  };
  /// The Gauss-Newton blocks at s over every stride-th event: the global
  /// block (V, bv; v's tangent in the basis Bv, then a for G = 5) and each
  /// cluster's.
  template <int G>
  void linearise(const State& s, int stride, const Eigen::Matrix<double, 3, 2>& Bv, Eigen::Matrix<double, G, G>& V,
                 Eigen::Matrix<double, G, 1>& bv, std::vector<ClusterBlocks<G>>& blocks) const;
  /// The damped Gauss-Newton step of the global unknowns (lambda times each
  /// block's diagonal added) with every cluster's lines eliminated (Schur
  /// complement); fills each block's X with U_d^-1 [W^T | bc].
  template <int G>
  static Eigen::Matrix<double, G, 1> dampedStep(const Eigen::Matrix<double, G, G>& V,
                                                const Eigen::Matrix<double, G, 1>& bv, double lambda,
                                                std::vector<ClusterBlocks<G>>& blocks);
  /// trial = s moved by the global step dg (v retracted in the basis Bv, a
  /// added) and each cluster's lines by their back-substituted step (kept
  /// where that step is not finite); trial has s's sizes.
  template <int G>
  static void takeStep(const State& s, const Eigen::Matrix<double, 3, 2>& Bv, const Eigen::Matrix<double, G, 1>& dg,
                       const std::vector<ClusterBlocks<G>>& blocks, State& trial);
  /// refine() with the global block of G unknowns: v's tangent (2), and a (5).
  template <int G>
  Result refineSteps(State s, int max_iterations, double function_tolerance, int stride,
                     const std::vector<State>& merge_into, double merge_rad) const;
  bool acceleration_ = false;
  /// The event terms as columns (joint_kernel.hpp), written once; the terms
  /// of cluster c are its rows [begin_[c], begin_[c + 1]). The buffer's
  /// memory is kept across problems (thread_buffer.hpp): allocating and releasing it
  /// per window made the kernel map and unmap its pages every time, which
  /// cost more than building the terms.
  JointColumns terms_{JointColumns::Spare::Full};
  std::vector<size_t> begin_{0};
  /// Every stride-th event of terms_, with the clusters' ranges in them,
  /// for a pass with a stride above 1; formed for the stride of the last
  /// such pass that asked (columns()).
  mutable JointColumns columns_;
  mutable std::vector<size_t> column_begin_;
  mutable int column_stride_ = 0;
  const JointColumns& columns(int stride) const;
  mutable std::vector<double> distances_;  // cost()'s under a loss other than Huber's, per event
  std::vector<Vec3> m1_, m3_;                  // fitted lines (frames), unit
  std::vector<int> obs_index_;                 // each cluster's index in the observations
  std::vector<unsigned char> left_out_;        // per cluster: 1 = left out (leaveOut)
  bool isLeftOut(size_t c) const { return !left_out_.empty() && left_out_[c]; }
  double focal_;
  RobustLoss loss_;
};

}  // namespace celc::detail
