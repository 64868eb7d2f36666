// Nonlinear refinement of the velocity direction with Ceres (Levenberg-Marquardt,
// Huber loss), optionally jointly with each cluster's boundary lines.
#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "refine.hpp"
#include "refine_costs.hpp"
#include "sampling.hpp"
#include "thread_buffer.hpp"

namespace celc {

namespace detail {

namespace {
constexpr size_t kChunk = 256;  // events per residual block

/// Holds a spare event-term buffer for one call and gives it back
/// (with whatever capacity it grew to) on every return.
class BorrowedTerms {
 public:
  BorrowedTerms() { borrowSpareVector<BorrowedTerms>(terms); }
  ~BorrowedTerms() { returnSpareVector<BorrowedTerms>(terms); }
  BorrowedTerms(const BorrowedTerms&) = delete;
  BorrowedTerms& operator=(const BorrowedTerms&) = delete;
  std::vector<EventTerm> terms;
};

/// A failed refinement's result: `status` with `message`.
SolverResult failure(SolveStatus status, const std::string& message) {
  SolverResult result;
  result.status = status;
  result.message = message;
  return result;
}

/// Why the refinement cannot start (options, initial direction, focal
/// length); nothing when it can.
std::optional<SolverResult> invalidInput(const WindowObservations& obs, const Vec3& initial,
                                         const RefineOptions& opt) {
  if (const std::string err = opt.validate(); !err.empty())
    return failure(SolveStatus::InvalidInput, "options: " + err);
  if (!initial.allFinite() || !(initial.norm() > 0.0) || !(obs.focal_px > 0.0))
    return failure(SolveStatus::InvalidInput, "initial velocity or focal length invalid");
  return std::nullopt;
}

/// The fitted plane normals (unit) of the usable clusters: m1 with `first`,
/// m3 otherwise.
std::vector<Vec3> fittedNormals(const WindowFrames& frames, bool first) {
  std::vector<Vec3> m;
  for (int c : frames.clusters()) m.push_back((first ? frames[c].m1 : frames[c].m3).normalized());
  return m;
}

/// The per-event terms of a seeded subset of each usable cluster's events
/// (max_events in all, RefineOptions::balance_clusters) with finite values,
/// appended to `terms` grouped by cluster: cluster ci's are
/// terms[begin[ci], begin[ci + 1]). Returns begin.
std::vector<size_t> collectTerms(const WindowObservations& obs, const MotionModel& motion,
                                 const WindowFrames& frames, int max_events, bool balance_clusters,
                                 std::uint64_t event_seed, std::vector<EventTerm>& terms) {
  const std::vector<int>& usable = frames.clusters();
  std::vector<size_t> sizes;
  for (int c : usable) sizes.push_back(obs.clusters[c].size());
  const std::vector<size_t> quota = rowQuota(sizes, static_cast<size_t>(std::max(0, max_events)), balance_clusters);
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
  return begin;
}

/// Adds the event terms to `problem` in blocks of kChunk events per cluster
/// under the Huber loss (huber_px): on v and the cluster's lines (m1[c],
/// m3[c]) with refine_lines, on v alone with the lines fixed otherwise. The
/// problem owns the returned costs; they point into `terms`.
std::vector<EventChunkCost*> addEventBlocks(ceres::Problem& problem, const std::vector<EventTerm>& terms,
                                            const std::vector<size_t>& begin, double focal_px, double huber_px,
                                            bool refine_lines, Vec3& v, std::vector<Vec3>& m1,
                                            std::vector<Vec3>& m3) {
  std::vector<EventChunkCost*> costs;
  for (size_t c = 0; c + 1 < begin.size(); ++c) {
    for (size_t b = begin[c]; b < begin[c + 1]; b += kChunk) {
      const size_t count = std::min(begin[c + 1], b + kChunk) - b;
      auto* cost = new EventChunkCost(terms.data() + b, count, focal_px, huber_px, refine_lines);
      costs.push_back(cost);
      if (refine_lines) {
        problem.AddResidualBlock(cost, nullptr, v.data(), m1[c].data(), m3[c].data());
      } else {
        cost->setFixedLines(m1[c], m3[c]);
        problem.AddResidualBlock(cost, nullptr, v.data());
      }
    }
  }
  return costs;
}

/// Puts v and (with refine_lines) every line in the problem on the unit sphere.
void setSphereManifolds(ceres::Problem& problem, ceres::SphereManifold<3>& sphere, Vec3& v,
                        std::vector<Vec3>& m1, std::vector<Vec3>& m3, bool refine_lines) {
  problem.SetManifold(v.data(), &sphere);
  if (!refine_lines) return;
  for (size_t i = 0; i < m1.size(); ++i) {
    if (!problem.HasParameterBlock(m1[i].data())) continue;
    problem.SetManifold(m1[i].data(), &sphere);
    problem.SetManifold(m3[i].data(), &sphere);
  }
}

/// Levenberg-Marquardt, silent, with opt's iterations, tolerance and
/// threads. Joint mode: the line blocks of each cluster are eliminated
/// (Schur complement), leaving a small system in v; v alone: 2 parameters.
ceres::Solver::Options solverOptions(const RefineOptions& opt, bool refine_lines) {
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = refine_lines ? ceres::DENSE_SCHUR : ceres::DENSE_QR;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.num_threads = opt.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  return so;
}

/// celc_opt's last solve, from the Huber solution v with the lines fixed,
/// under the Cauchy loss (refine.cauchy_scale; or Tukey's biweight,
/// refine.tukey_scale) where the residuals at v have a heavier tail than
/// Gaussian noise gives (other edges' events, a line's stub): they stop
/// pulling. v is kept where that solve fails. Returns its iterations (0
/// where it does not run).
int redescendingSolve(ceres::Problem& problem, const ceres::Solver::Options& so,
                      const std::vector<EventChunkCost*>& costs, const std::vector<EventTerm>& terms,
                      const std::vector<size_t>& begin, const std::vector<Vec3>& m1, const std::vector<Vec3>& m3,
                      double focal_px, const RefineOptions& opt, Vec3& v) {
  const Vec3 huber_v = v, vh = v.normalized();
  std::vector<double> d;
  d.reserve(terms.size());
  for (size_t c = 0; c + 1 < begin.size(); ++c)
    for (size_t k = begin[c]; k < begin[c + 1]; ++k)
      d.push_back(eventDistance(terms[k], vh, m1[c], m3[c], focal_px, nullptr, nullptr, nullptr));
  const ResidualSpread spread = residualSpread(std::move(d));
  const RobustLoss loss = redescendingLoss(opt.cauchy_scale, opt.tukey_scale,
                                           [&](double k) { return spread.cauchyScale(k, opt.cauchy_min_tail); });
  if (loss.type == RobustLoss::Type::None) return 0;
  for (EventChunkCost* cost : costs) cost->setLoss(loss);
  ceres::Solver::Summary last;
  ceres::Solve(so, &problem, &last);
  if (!last.IsSolutionUsable() || !v.allFinite()) v = huber_v;
  return static_cast<int>(last.iterations.size());
}

}  // namespace

SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& opt,
                            const WindowFrames& frames, int max_events, std::uint64_t event_seed) {
  const auto start = std::chrono::steady_clock::now();
  if (std::optional<SolverResult> invalid = invalidInput(obs, initial, opt)) return *invalid;
  Vec3 v = initial.normalized();
  // Lines: reference-frame plane normals (unit); free parameters in joint mode.
  std::vector<Vec3> m1 = fittedNormals(frames, true), m3 = fittedNormals(frames, false);
  // The event terms are declared before the problem, whose costs point into them.
  BorrowedTerms borrowed;
  const std::vector<size_t> begin =
      collectTerms(obs, motion, frames, max_events, opt.balance_clusters, event_seed, borrowed.terms);
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::SphereManifold<3> sphere;
  const std::vector<EventChunkCost*> costs =
      addEventBlocks(problem, borrowed.terms, begin, obs.focal_px, opt.huber_px, refine_lines, v, m1, m3);
  const int n_res = static_cast<int>(borrowed.terms.size());  // one residual per event
  if (n_res < 3) {
    SolverResult result = failure(SolveStatus::Degenerate, "too few events to refine");
    result.degeneracy = Degeneracy::TooFewClusters;
    return result;
  }
  setSphereManifolds(problem, sphere, v, m1, m3, refine_lines);
  const ceres::Solver::Options so = solverOptions(opt, refine_lines);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  SolverResult result;
  if (opt.cauchy_scale > 0.0 && !refine_lines && summary.IsSolutionUsable())
    result.iterations += redescendingSolve(problem, so, costs, borrowed.terms, begin, m1, m3, obs.focal_px, opt, v);

  const Vec3 vr = v.normalized();
  result.iterations += static_cast<int>(summary.iterations.size());
  result.rows_used = n_res;
  if (!summary.IsSolutionUsable() || !vr.allFinite()) {
    result.status = SolveStatus::Failed;
    result.message = "ceres: " + summary.message;
  } else {
    result.status = SolveStatus::Ok;
    result.v = vr.dot(initial) < 0 ? Vec3(-vr) : vr;  // keep the resolved sign
    // The residual reported is the Huber cost's.
    result.residual_px = std::sqrt(2.0 * summary.final_cost / std::max(1, n_res));
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
