// celc_ml's joint Levenberg-Marquardt with the lines eliminated per cluster.
#include "joint_refine.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "refine_costs.hpp"
#include "sampling.hpp"
#include "solve_spd4.hpp"
#include "sphere_tangent.hpp"
#include "thread_buffer.hpp"

namespace celc::detail {

namespace {

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;
using Mat24 = Eigen::Matrix<double, 2, 4>;

constexpr double kStepTolerance = 1e-8;  // [rad]

/// x moved by the tangent step B delta, back on the sphere.
Vec3 retract(const Vec3& x, const Mat32& B, const Eigen::Vector2d& delta) {
  return (x + B * delta).normalized();
}

/// a and b within the angle of cosine min_cos in v and in every line
/// normal (unit vectors, sign-agnostic).
bool near(const JointProblem::State& a, const JointProblem::State& b, double min_cos) {
  if (std::abs(a.v.dot(b.v)) < min_cos || a.m1.size() != b.m1.size()) return false;
  for (size_t c = 0; c < a.m1.size(); ++c)
    if (std::abs(a.m1[c].dot(b.m1[c])) < min_cos || std::abs(a.m3[c].dot(b.m3[c])) < min_cos) return false;
  return true;
}

}  // namespace

JointProblem::JointProblem(const WindowObservations& obs, const MotionModel& motion,
                           const WindowFrames& frames, int max_events, bool balance_clusters,
                           std::uint64_t event_seed, double huber_px, bool acceleration)
    : acceleration_(acceleration), focal_(obs.focal_px), loss_(RobustLoss::huber(huber_px)) {
  const double t_ref = motion.referenceTime();
  auto q = [t_ref](double t) { return 0.5 * (t - t_ref) * (t - t_ref); };
  const std::vector<int>& usable = frames.clusters();
  std::vector<size_t> sizes;
  for (int c : usable) sizes.push_back(obs.clusters[c].size());
  const std::vector<size_t> quota =
      rowQuota(sizes, static_cast<size_t>(std::max(0, max_events)), balance_clusters);
  // sampleIndices' count per cluster: all of a cluster whose quota is 0 or
  // above its size.
  size_t total = 0;
  for (size_t i = 0; i < quota.size(); ++i) total += quota[i] == 0 || quota[i] >= sizes[i] ? sizes[i] : quota[i];
  terms_.startRows(total, acceleration_);
  for (size_t ci = 0; ci < usable.size(); ++ci) {
    const ClusterObservation& cl = obs.clusters[usable[ci]];
    const ClusterFrame& frame = frames[usable[ci]];
    const size_t first = terms_.size();
    const double qe = q(cl.l3.t), qs = q(cl.l1.t);
    for (size_t k : sampleIndices(cl.size(), quota[ci], event_seed + ci)) {
      const double t = cl.times[k];
      const Vec3& f = cl.bearings[k];
      if (!f.allFinite() || !std::isfinite(t)) continue;
      Mat3 Rk, Pk;
      motion.pose(t, Rk, Pk);
      const EventTerm e = makeEventTerm(frame, Rk, Pk, f);
      if (!e.fp.allFinite() || !e.De.allFinite() || !e.Ds.allFinite()) continue;
      terms_.appendRow(e, acceleration_ ? Eigen::Vector2d(qe - q(t), qs - q(t)) : Eigen::Vector2d::Zero());
    }
    if (terms_.size() == first) continue;
    begin_.push_back(terms_.size());
    m1_.push_back(frame.m1.normalized());
    m3_.push_back(frame.m3.normalized());
    obs_index_.push_back(usable[ci]);
  }
}

void JointProblem::leaveOut(const std::vector<size_t>& clusters) {
  left_out_.resize(begin_.size() - 1, 0);
  for (size_t c : clusters)
    if (c < left_out_.size()) left_out_[c] = 1;
}

void JointProblem::takeBack(size_t c) {
  if (c < left_out_.size()) left_out_[c] = 0;
}

const JointColumns& JointProblem::columns(int stride) const {
  if (stride <= 1) {  // the terms themselves
    if (column_stride_ != 1) column_begin_ = begin_, column_stride_ = 1;
    return terms_;
  }
  if (stride != column_stride_) {
    columns_.assignStrided(terms_, begin_, static_cast<size_t>(stride), column_begin_);
    column_stride_ = stride;
  }
  return columns_;
}

JointProblem::~JointProblem() = default;

size_t JointProblem::events() const { return terms_.size(); }

ResidualSpread JointProblem::spread(const State& s) const {
  if (!acceleration_) {
    std::vector<double> d;
    d.reserve(terms_.size());
    for (size_t c = 0; c + 1 < begin_.size(); ++c)
      for (size_t k = begin_[c]; k < begin_[c + 1] && !isLeftOut(c); ++k)
        d.push_back(eventDistance(terms_.term(k), s.v, s.m1[c], s.m3[c], focal_, nullptr, nullptr, nullptr));
    return residualSpread(std::move(d));
  }
  const JointColumns& cols = columns(1);
  std::vector<double> d(cols.size());
  for (size_t c = 0; c + 1 < column_begin_.size(); ++c)
    jointDistances(cols, column_begin_[c], column_begin_[c + 1], s.v, s.m1[c], s.m3[c], focal_,
                   d.data() + column_begin_[c], &s.a);
  return residualSpread(std::move(d));
}

double JointProblem::robustScale(const State& s) const { return spread(s).scale; }

JointProblem::State JointProblem::start(const Vec3& v, const Vec3& a) const {
  const double n = v.norm();
  return {v / n, m1_, m3_, acceleration_ ? Vec3(a / n) : Vec3::Zero()};
}

double JointProblem::cost(const State& s, int stride) const {
  double total = 0.0;
  if (loss_.type == RobustLoss::Type::Huber) {
    const JointColumns& cols = columns(stride);
    for (size_t c = 0; c + 1 < column_begin_.size(); ++c)
      if (!isLeftOut(c))
        total += jointHuberCost(cols, column_begin_[c], column_begin_[c + 1], s.v, s.m1[c], s.m3[c], focal_,
                              loss_.scale, acceleration_ ? &s.a : nullptr);
    return 0.5 * total;  // +inf when a distance is not finite
  }
  const JointColumns& cols = columns(stride);
  distances_.resize(cols.size());
  for (size_t c = 0; c + 1 < column_begin_.size(); ++c)
    jointDistances(cols, column_begin_[c], column_begin_[c + 1], s.v, s.m1[c], s.m3[c], focal_,
                   distances_.data() + column_begin_[c], acceleration_ ? &s.a : nullptr);
  for (size_t c = 0; c + 1 < column_begin_.size(); ++c) {
    if (isLeftOut(c)) continue;
    for (size_t i = column_begin_[c]; i < column_begin_[c + 1]; ++i) {
      const double d = distances_[i];
      if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
      total += loss_.rho(d);
    }
  }
  return 0.5 * total;
}

template <int G>
void JointProblem::linearise(const State& s, int stride, const Mat32& Bv, Eigen::Matrix<double, G, G>& V,
                             Eigen::Matrix<double, G, 1>& bv, std::vector<ClusterBlocks<G>>& blocks) const {
  const JointColumns& cols = columns(stride);
  V.setZero();
  bv.setZero();
  for (size_t c = 0; c + 1 < begin_.size(); ++c) {
    ClusterBlocks<G>& k = blocks[c];
    k.B1 = tangentBasis(s.m1[c]);
    k.B3 = tangentBasis(s.m3[c]);
    if (isLeftOut(c)) {  // no terms: its lines do not move
      k.U.setIdentity();
      k.W.setZero();
      k.bc.setZero();
      k.bg.setZero();
      k.Vc.setZero();
      continue;
    }
    // An event whose distance is not finite adds nothing (not at s: its
    // cost is finite).
    const double *sum_v, *sum_bv, *sum_u, *sum_w, *sum_bc;
    JointBlockSums b;
    JointAccelerationSums ba;
    if constexpr (G == 2) {
      b = jointBlockSums(cols, column_begin_[c], column_begin_[c + 1], s.v, s.m1[c], s.m3[c], Bv.data(),
                         k.B1.data(), k.B3.data(), focal_, loss_);
      sum_v = b.V, sum_bv = b.bv, sum_u = b.U, sum_w = b.W, sum_bc = b.bc;
    } else {
      ba = jointAccelerationSums(cols, column_begin_[c], column_begin_[c + 1], s.v, s.a, s.m1[c], s.m3[c],
                                 Bv.data(), k.B1.data(), k.B3.data(), focal_, loss_);
      sum_v = ba.G, sum_bv = ba.bg, sum_u = ba.U, sum_w = ba.W, sum_bc = ba.bc;
    }
    for (int i = 0, n = 0; i < G; ++i)
      for (int j = i; j < G; ++j, ++n) k.Vc(i, j) = k.Vc(j, i) = sum_v[n];
    V += k.Vc;
    for (int i = 0; i < G; ++i) k.bg(i) = sum_bv[i];
    bv += k.bg;
    for (int i = 0, n = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j, ++n) k.U(i, j) = k.U(j, i) = sum_u[n];
    for (int i = 0; i < G; ++i)
      for (int j = 0; j < 4; ++j) k.W(i, j) = sum_w[4 * i + j];
    k.bc = Vec4(sum_bc[0], sum_bc[1], sum_bc[2], sum_bc[3]);
  }
}

Eigen::MatrixXd JointProblem::information(const State& s) const {
  const Mat32 Bv = tangentBasis(s.v);
  auto reduce = [&](auto g) -> Eigen::MatrixXd {
    constexpr int G = decltype(g)::value;
    std::vector<ClusterBlocks<G>> blocks(begin_.size() - 1);
    Eigen::Matrix<double, G, G> V;
    Eigen::Matrix<double, G, 1> bv;
    linearise<G>(s, 1, Bv, V, bv, blocks);
    // The lines eliminated: V - sum W U^-1 W^T (a line the events do not
    // fix adds nothing, as the pseudo-inverse of solveSpd4 does).
    for (ClusterBlocks<G>& k : blocks) {
      k.X.template leftCols<G>() = k.W.transpose();
      k.X.col(G).setZero();
      solveSpd4(k.U, k.X);
      V.noalias() -= k.X.template leftCols<G>().transpose() * k.W.transpose();
    }
    return 0.5 * (V + V.transpose());
  };
  return acceleration_ ? reduce(std::integral_constant<int, 5>{}) : reduce(std::integral_constant<int, 2>{});
}

Eigen::MatrixXd JointProblem::clusterRobustCovariance(const State& s) const {
  const Mat32 Bv = tangentBasis(s.v);
  auto sandwich = [&](auto g) -> Eigen::MatrixXd {
    constexpr int G = decltype(g)::value;
    const size_t K = begin_.size() - 1;
    const Eigen::MatrixXd nan = Eigen::MatrixXd::Constant(G, G, NAN);
    if (K <= static_cast<size_t>(G)) return nan;
    std::vector<ClusterBlocks<G>> blocks(K);
    Eigen::Matrix<double, G, G> V, B = Eigen::Matrix<double, G, G>::Zero();
    Eigen::Matrix<double, G, 1> bv;
    linearise<G>(s, 1, Bv, V, bv, blocks);
    for (ClusterBlocks<G>& k : blocks) {
      k.X.template leftCols<G>() = k.W.transpose();
      k.X.col(G) = k.bc;
      solveSpd4(k.U, k.X);
      V.noalias() -= k.X.template leftCols<G>().transpose() * k.W.transpose();
      // The efficient score: the gradient with the cluster's lines at their
      // own optimum for the current global unknowns.
      const Eigen::Matrix<double, G, 1> score = k.bg - k.X.template leftCols<G>().transpose() * k.bc;
      if (score.allFinite()) B.noalias() += score * score.transpose();
    }
    const Eigen::Matrix<double, G, G> H = 0.5 * (V + V.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, G, G>> es(H);
    if (es.info() != Eigen::Success || !(es.eigenvalues()(0) > 1e-12 * std::max(es.eigenvalues()(G - 1), 1e-300)))
      return nan;
    const Eigen::Matrix<double, G, G> Hinv =
        es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
    return Hinv * B * Hinv * (static_cast<double>(K) / static_cast<double>(K - G));
  };
  return acceleration_ ? sandwich(std::integral_constant<int, 5>{}) : sandwich(std::integral_constant<int, 2>{});
}

std::vector<double> JointProblem::clusterAgreement(const State& s, double sigma_px) const {
  if (acceleration_) return {};
  const size_t K = begin_.size() - 1;
  std::vector<ClusterBlocks<2>> blocks(K);
  Eigen::Matrix2d V;
  Eigen::Vector2d bv;
  linearise<2>(s, 1, tangentBasis(s.v), V, bv, blocks);
  // Per cluster: H_k = V_k - W_k U_k^-1 W_k^T and g_k = bg_k - W_k U_k^-1 bc_k.
  std::vector<Eigen::Matrix2d> Hk(K);
  std::vector<Eigen::Vector2d> gk(K);
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (size_t c = 0; c < K; ++c) {
    ClusterBlocks<2>& k = blocks[c];
    k.X.leftCols<2>() = k.W.transpose();
    k.X.col(2) = k.bc;
    solveSpd4(k.U, k.X);
    Hk[c] = k.Vc - k.X.leftCols<2>().transpose() * k.W.transpose();
    Hk[c] = 0.5 * (Hk[c] + Hk[c].transpose()).eval();
    gk[c] = k.bg - k.X.leftCols<2>().transpose() * k.bc;
    if (!isLeftOut(c)) H += Hk[c];
  }
  const double s2 = sigma_px * sigma_px;
  // H_k^+ over the eigenvalues above 1e-9 of H's largest (a line fixes v's
  // tangent in one direction or two).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eh(H, Eigen::EigenvaluesOnly);
  const double floor = 1e-9 * std::max(eh.eigenvalues()(1), 1e-300);
  std::vector<double> T(K, NAN);
  for (size_t c = 0; c < K; ++c) {
    if (isLeftOut(c) || !Hk[c].allFinite() || !gk[c].allFinite() || !(s2 > 0.0)) continue;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> ek(Hk[c]);
    Eigen::Matrix2d Hk_pinv = Eigen::Matrix2d::Zero();
    for (int i = 0; i < 2; ++i)
      if (ek.eigenvalues()(i) > floor)
        Hk_pinv += ek.eigenvectors().col(i) * ek.eigenvectors().col(i).transpose() / ek.eigenvalues()(i);
    const Eigen::Matrix2d A = H - Hk[c];
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> ea(A);
    if (!(ea.eigenvalues()(0) > floor)) continue;
    const Eigen::Matrix2d A_inv =
        ea.eigenvectors() * ea.eigenvalues().cwiseInverse().asDiagonal() * ea.eigenvectors().transpose();
    T[c] = gk[c].dot((Hk_pinv + A_inv) * gk[c]) / s2;
  }
  return T;
}

JointProblem::Result JointProblem::refineConstantVelocity(State s, int max_iterations, double function_tolerance,
                                                          int stride) const {
  s.a.setZero();
  return refineSteps<2>(std::move(s), max_iterations, function_tolerance, stride, {}, 0.0);
}

JointProblem::Result JointProblem::refine(State s, int max_iterations, double function_tolerance,
                                          int stride, const std::vector<State>& merge_into,
                                          double merge_rad) const {
  return acceleration_ ? refineSteps<5>(std::move(s), max_iterations, function_tolerance, stride, merge_into, merge_rad)
                       : refineSteps<2>(std::move(s), max_iterations, function_tolerance, stride, merge_into, merge_rad);
}

template <int G>
Eigen::Matrix<double, G, 1> JointProblem::dampedStep(const Eigen::Matrix<double, G, G>& V,
                                                     const Eigen::Matrix<double, G, 1>& bv, double lambda,
                                                     std::vector<ClusterBlocks<G>>& blocks) {
  Eigen::Matrix<double, G, G> S = V;
  S.diagonal() += lambda * V.diagonal().cwiseMax(1e-12);
  Eigen::Matrix<double, G, 1> rhs = -bv;
  for (ClusterBlocks<G>& k : blocks) {
    Mat4 Ud = k.U;
    Ud.diagonal() += lambda * k.U.diagonal().cwiseMax(1e-12);
    k.X.template leftCols<G>() = k.W.transpose();
    k.X.col(G) = k.bc;
    solveSpd4(Ud, k.X);
    S.noalias() -= k.X.template leftCols<G>().transpose() * k.W.transpose();
    rhs.noalias() += k.X.template leftCols<G>().transpose() * k.bc;
  }
  return S.ldlt().solve(rhs);
}

template <int G>
void JointProblem::takeStep(const State& s, const Eigen::Matrix<double, 3, 2>& Bv,
                            const Eigen::Matrix<double, G, 1>& dg, const std::vector<ClusterBlocks<G>>& blocks,
                            State& trial) {
  trial.v = retract(s.v, Bv, dg.template head<2>());
  if constexpr (G == 5) trial.a = s.a + dg.template tail<3>();
  for (size_t c = 0; c < blocks.size(); ++c) {
    // dc = -U_d^-1 (bc + W^T dg), from the columns dampedStep solved.
    const ClusterBlocks<G>& k = blocks[c];
    const Vec4 dc = -(k.X.col(G) + k.X.template leftCols<G>() * dg);
    if (!dc.allFinite()) {
      trial.m1[c] = s.m1[c];
      trial.m3[c] = s.m3[c];
      continue;
    }
    trial.m1[c] = retract(s.m1[c], k.B1, dc.template head<2>());
    trial.m3[c] = retract(s.m3[c], k.B3, dc.template tail<2>());
  }
}

template <int G>
JointProblem::Result JointProblem::refineSteps(State s, int max_iterations, double function_tolerance,
                                               int stride, const std::vector<State>& merge_into,
                                               double merge_rad) const {
  using MatG = Eigen::Matrix<double, G, G>;
  using VecG = Eigen::Matrix<double, G, 1>;
  const double merge_cos = std::cos(merge_rad);
  Result out;
  const size_t nc = begin_.size() - 1;
  for (size_t c = 0; c < nc; ++c)
    if (!isLeftOut(c)) out.events += static_cast<int>((begin_[c + 1] - begin_[c] + stride - 1) / stride);
  double f = cost(s, stride);
  if (!std::isfinite(f) || out.events < 3) return out;
  std::vector<ClusterBlocks<G>> blocks(nc);
  double lambda = 1e-4;
  State trial = s;
  for (int it = 0; it < max_iterations; ++it) {
    out.iterations = it + 1;
    // Linearise: the Gauss-Newton blocks of Huber's r = sqrt(rho(d)) at s,
    // or of r = sqrt(w(d_s)) d with the weights frozen at s (Cauchy: IRLS).
    // The global block: v's tangent, then (G = 5) the acceleration.
    const Mat32 Bv = tangentBasis(s.v);
    MatG V;
    VecG bv;
    linearise<G>(s, stride, Bv, V, bv, blocks);
    // Damped steps until one lowers the cost (lambda grows on failure).
    bool accepted = false;
    for (int tries = 0; tries < 12 && !accepted; ++tries) {
      const VecG dg = dampedStep<G>(V, bv, lambda, blocks);
      if (!dg.allFinite()) {
        lambda *= 10.0;
        continue;
      }
      const Eigen::Vector2d dv = dg.template head<2>();
      takeStep<G>(s, Bv, dg, blocks, trial);
      const double ft = cost(trial, stride);
      if (ft < f) {
        const double decrease = (f - ft) / std::max(f, 1e-300);
        std::swap(s, trial);
        f = ft;
        lambda = std::max(lambda / 3.0, 1e-12);
        accepted = true;
        // Converged: the cost or v no longer moves (v's step below
        // kStepTolerance rad, as Ceres' parameter tolerance; with an
        // acceleration, a's step below it times |a| or 1).
        const bool a_still = G == 2 || dg.template tail<G - 2>().norm() < kStepTolerance * std::max(1.0, s.a.norm());
        if (decrease < function_tolerance || (dv.norm() < kStepTolerance && a_still)) it = max_iterations;
        for (const State& e : merge_into)
          if (merge_rad > 0.0 && near(e, s, merge_cos)) {
            out.merged = true;
            it = max_iterations;
          }
      } else {
        lambda *= 4.0;
      }
    }
    if (!accepted) break;  // no step lowers the cost: a minimum at this precision
  }
  out.state = std::move(s);
  out.cost = f;
  out.ok = std::isfinite(f) && out.state.v.allFinite() && out.state.a.allFinite();
  return out;
}

}  // namespace celc::detail
