// Nonlinear refinement of the velocity direction with Ceres (Levenberg-Marquardt,
// Huber loss), optionally jointly with each cluster's boundary lines.
#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <random>

#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"
#include "refine_costs.hpp"

namespace celc {
namespace {

/// The same distance with the cluster's lines free (reference-frame normals m1, m3):
///   u = D_e^T m3, s = D_s^T m1, l_ref = m1 (u.v) - m3 (s.v),
///   d = focal * f'.l_ref / |(R_k^T l_ref)_{1,2}|,  f' = R_k f,  D = P(t_line) - P(t_k).
struct JointEventLineDistance {
  Vec3 fp;
  Eigen::Matrix<double, 2, 3> Rt01;  // first two rows of R_k^T
  Mat3 De, Ds;
  double focal;

  template <typename T>
  bool operator()(const T* v_, const T* m1_, const T* m3_, T* residual) const {
    using V3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const V3> v(v_), m1(m1_), m3(m3_);
    const V3 u = De.transpose().cast<T>() * m3;
    const V3 s = Ds.transpose().cast<T>() * m1;
    const V3 l = m1 * u.dot(v) - m3 * s.dot(v);
    const Eigen::Matrix<T, 2, 1> g = Rt01.cast<T>() * l;
    const T gn = g.norm();
    if (!(gn > T(1e-300))) return false;
    residual[0] = T(focal) * fp.cast<T>().dot(l) / gn;
    return true;
  }
};

std::vector<size_t> subset(size_t n, int max_events, std::uint64_t seed) {
  std::vector<size_t> idx(n);
  for (size_t i = 0; i < n; ++i) idx[i] = i;
  if (max_events > 0 && static_cast<size_t>(max_events) < n) {
    std::mt19937_64 rng(seed);
    std::shuffle(idx.begin(), idx.end(), rng);
    idx.resize(static_cast<size_t>(max_events));
    std::sort(idx.begin(), idx.end());
  }
  return idx;
}

}  // namespace

SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  SolverResult result;
  if (const std::string err = opt.validate(); !err.empty()) {
    result.status = SolveStatus::InvalidInput;
    result.message = "options: " + err;
    return result;
  }
  if (!initial.allFinite() || !(initial.norm() > 0.0) || !(obs.focal_px > 0.0)) {
    result.status = SolveStatus::InvalidInput;
    result.message = "initial velocity or focal length invalid";
    return result;
  }
  const std::vector<int> usable = detail::usableClusters(obs, 2);
  std::vector<size_t> offsets{0};
  for (int c : usable) offsets.push_back(offsets.back() + obs.clusters[c].size());
  const std::vector<size_t> pick = subset(offsets.back(), opt.max_events, opt.seed);

  double v[3] = {initial.x(), initial.y(), initial.z()};
  Eigen::Map<Vec3>(v).normalize();
  // Line parameters (joint mode): reference-frame normals, unit norm.
  std::vector<Vec3> m1(usable.size()), m3(usable.size());
  std::vector<detail::ClusterFrame> frames;
  for (size_t i = 0; i < usable.size(); ++i) {
    frames.push_back(detail::makeClusterFrame(obs.clusters[usable[i]], motion));
    m1[i] = frames.back().m1.normalized();
    m3[i] = frames.back().m3.normalized();
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::HuberLoss loss(opt.huber_px);
  ceres::SphereManifold<3> sphere;
  size_t ci = 0;
  int n_res = 0;
  for (size_t flat : pick) {
    while (flat >= offsets[ci + 1]) ++ci;
    const auto& cl = obs.clusters[usable[ci]];
    const size_t k = flat - offsets[ci];
    const double t = cl.times[k];
    const Vec3& f = cl.bearings[k];
    if (!f.allFinite() || !std::isfinite(t)) continue;
    if (!refine_lines) {
      const detail::ConstraintRow row = detail::celcRow(frames[ci], motion, t, f);
      if (!row.a.allFinite() || !row.N.allFinite()) continue;
      problem.AddResidualBlock(
          new detail::EventLineDistance(row.a, row.N.topRows<2>(), obs.focal_px), &loss, v);
    } else {
      const Mat3 Rk = motion.rotation(t), Pk = motion.positionMatrix(t);
      auto* functor = new JointEventLineDistance{Rk * f, Rk.transpose().topRows<2>(),
                                                 frames[ci].Pe - Pk, frames[ci].Ps - Pk,
                                                 obs.focal_px};
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<JointEventLineDistance, 1, 3, 3, 3>(functor), &loss, v,
          m1[ci].data(), m3[ci].data());
    }
    ++n_res;
  }
  if (n_res < 3) {
    result.status = SolveStatus::Degenerate;
    result.degeneracy = Degeneracy::TooFewClusters;
    result.message = "too few events to refine";
    return result;
  }
  problem.SetManifold(v, &sphere);
  if (refine_lines)
    for (size_t i = 0; i < usable.size(); ++i) {
      if (!problem.HasParameterBlock(m1[i].data())) continue;
      problem.SetManifold(m1[i].data(), &sphere);
      problem.SetManifold(m3[i].data(), &sphere);
    }

  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = refine_lines ? ceres::DENSE_SCHUR : ceres::DENSE_QR;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.num_threads = opt.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  const Vec3 vr = Eigen::Map<const Vec3>(v).normalized();
  result.iterations = static_cast<int>(summary.iterations.size());
  result.rows_used = n_res;
  if (!summary.IsSolutionUsable() || !vr.allFinite()) {
    result.status = SolveStatus::Failed;
    result.message = "ceres: " + summary.message;
  } else {
    result.status = SolveStatus::Ok;
    result.v = vr.dot(initial) < 0 ? Vec3(-vr) : vr;  // keep the resolved sign
    result.residual_px = std::sqrt(2.0 * summary.final_cost / std::max(1, n_res));
  }
  result.time_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace celc
