// Nonlinear refinement of the velocity direction with Ceres (Levenberg-Marquardt,
// Huber loss), optionally jointly with each cluster's boundary lines.
#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "refine.hpp"
#include "refine_costs.hpp"
#include "sampling.hpp"
#include "thread_buffer.hpp"

namespace celc {

namespace detail {

namespace {
constexpr size_t kChunk = 256;  // events per residual block

/// Holds the thread's event-term buffer for one call and gives it back
/// (with whatever capacity it grew to) on every return.
class BorrowedTerms {
 public:
  BorrowedTerms() { borrowThreadVector<BorrowedTerms>(terms); }
  ~BorrowedTerms() { returnThreadVector<BorrowedTerms>(terms); }
  BorrowedTerms(const BorrowedTerms&) = delete;
  BorrowedTerms& operator=(const BorrowedTerms&) = delete;
  std::vector<EventTerm> terms;
};
}  // namespace

SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& opt,
                            const WindowFrames& frames, int max_events, std::uint64_t event_seed) {
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
  const std::vector<int>& usable = frames.clusters();
  std::vector<size_t> sizes;
  for (int c : usable) sizes.push_back(obs.clusters[c].size());
  const std::vector<size_t> quota =
      rowQuota(sizes, static_cast<size_t>(std::max(0, max_events)), opt.balance_clusters);

  Vec3 v = initial.normalized();
  // Lines: reference-frame plane normals (unit); free parameters in joint mode.
  std::vector<Vec3> m1(usable.size()), m3(usable.size());
  for (size_t i = 0; i < usable.size(); ++i) {
    m1[i] = frames[usable[i]].m1.normalized();
    m3[i] = frames[usable[i]].m3.normalized();
  }
  // Per-event terms grouped by cluster (a seeded subset of each): cluster
  // ci's are terms[begin[ci], begin[ci + 1]). Declared before the problem,
  // whose costs point into them.
  BorrowedTerms borrowed;
  std::vector<EventTerm>& terms = borrowed.terms;
  size_t total = 0;
  for (size_t q : quota) total += q;
  reserveWithHeadroom(terms, total);
  std::vector<size_t> begin{0};
  for (size_t ci = 0; ci < usable.size(); ++ci) {
    const auto& cl = obs.clusters[usable[ci]];
    for (size_t k : sampleIndices(cl.size(), quota[ci], event_seed + ci)) {
      const double t = cl.times[k];
      const Vec3& f = cl.bearings[k];
      if (!f.allFinite() || !std::isfinite(t)) continue;
      const Mat3 Rk = motion.rotation(t), Pk = motion.positionMatrix(t);
      const EventTerm e = makeEventTerm(frames[usable[ci]], Rk, Pk, f);
      if (e.fp.allFinite() && e.De.allFinite() && e.Ds.allFinite()) terms.push_back(e);
    }
    begin.push_back(terms.size());
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::SphereManifold<3> sphere;
  int n_res = 0;
  std::vector<EventChunkCost*> costs;
  for (size_t c = 0; c < usable.size(); ++c) {
    for (size_t b = begin[c]; b < begin[c + 1]; b += kChunk) {
      const size_t count = std::min(begin[c + 1], b + kChunk) - b;
      n_res += static_cast<int>(count);
      auto* cost = new EventChunkCost(terms.data() + b, count, obs.focal_px, opt.huber_px, refine_lines);
      costs.push_back(cost);
      if (refine_lines) {
        problem.AddResidualBlock(cost, nullptr, v.data(), m1[c].data(), m3[c].data());
      } else {
        cost->setFixedLines(m1[c], m3[c]);
        problem.AddResidualBlock(cost, nullptr, v.data());
      }
    }
  }
  if (n_res < 3) {
    result.status = SolveStatus::Degenerate;
    result.degeneracy = Degeneracy::TooFewClusters;
    result.message = "too few events to refine";
    return result;
  }
  problem.SetManifold(v.data(), &sphere);
  if (refine_lines)
    for (size_t i = 0; i < usable.size(); ++i) {
      if (!problem.HasParameterBlock(m1[i].data())) continue;
      problem.SetManifold(m1[i].data(), &sphere);
      problem.SetManifold(m3[i].data(), &sphere);
    }

  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // Joint mode: the line blocks of each cluster are eliminated (Schur
  // complement), leaving a small system in v; v alone: 2 parameters.
  so.linear_solver_type = refine_lines ? ceres::DENSE_SCHUR : ceres::DENSE_QR;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.num_threads = opt.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  // The residual reported is the Huber cost's.
  const double huber_cost = summary.final_cost;
  // celc_opt: a last solve under the Cauchy loss (refine.cauchy_scale; or
  // Tukey's biweight, refine.tukey_scale) where
  // the residuals at the Huber solution have a heavier tail than Gaussian
  // noise gives (other edges' events, a line's stub): they stop pulling.
  if (opt.cauchy_scale > 0.0 && !refine_lines && summary.IsSolutionUsable()) {
    const Vec3 huber_v = v, vh = v.normalized();
    std::vector<double> d;
    d.reserve(static_cast<size_t>(n_res));
    for (size_t c = 0; c < usable.size(); ++c)
      for (size_t k = begin[c]; k < begin[c + 1]; ++k)
        d.push_back(eventDistance(terms[k], vh, m1[c], m3[c], obs.focal_px, nullptr, nullptr, nullptr));
    const ResidualSpread spread = residualSpread(std::move(d));
    const double cauchy_px = spread.cauchyScale(opt.cauchy_scale, opt.cauchy_min_tail);
    if (cauchy_px > 0.0) {
      const double tukey_px = opt.tukey_scale > 0.0 ? spread.cauchyScale(opt.tukey_scale, opt.cauchy_min_tail) : 0.0;
      for (EventChunkCost* cost : costs) {
        if (tukey_px > 0.0)
          cost->setTukey(tukey_px);
        else
          cost->setCauchy(cauchy_px);
      }
      ceres::Solver::Summary cauchy;
      ceres::Solve(so, &problem, &cauchy);
      result.iterations += static_cast<int>(cauchy.iterations.size());
      if (!cauchy.IsSolutionUsable() || !v.allFinite()) v = huber_v;
    }
  }

  const Vec3 vr = v.normalized();
  result.iterations += static_cast<int>(summary.iterations.size());
  result.rows_used = n_res;
  if (!summary.IsSolutionUsable() || !vr.allFinite()) {
    result.status = SolveStatus::Failed;
    result.message = "ceres: " + summary.message;
  } else {
    result.status = SolveStatus::Ok;
    result.v = vr.dot(initial) < 0 ? Vec3(-vr) : vr;  // keep the resolved sign
    result.residual_px = std::sqrt(2.0 * huber_cost / std::max(1, n_res));
  }
  result.time_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace detail

SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& options) {
  return detail::refineVelocity(obs, motion, initial, refine_lines, options,
                                detail::WindowFrames(obs, motion), options.max_events, options.seed);
}

}  // namespace celc
