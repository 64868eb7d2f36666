// CELC with a constant acceleration (celc_acc.hpp).
#include "celc_acc.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "joint_refine.hpp"
#include "linear_method.hpp"
#include "robust_nullspace.hpp"
#include "sampling.hpp"
#include "sign_test.hpp"
#include "stopwatch.hpp"
#include "window_checks.hpp"

namespace celc::detail {

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat26 = Eigen::Matrix<double, 2, 6>;

/// One event's row: residual r = a^T x / |N x| [normalised units].
struct AccRow {
  Vec6 a;
  Mat26 N;
};

// IRLS steps at most: the linear (v, a) is a start of the joint
// refinement, which needs its basin, not its minimum.
constexpr int kMaxIterations = 5;
// Rows of the linear stage at most (a start: 5 unknowns).
constexpr std::size_t kMaxRows = 400;
// The joint refinement stops where a step lowers the cost by less than this
// share (or refine.function_tolerance, if larger): with N events that is
// N 1e-7 likelihood units, far below what moves the estimate; the valley of
// v and a is long and Levenberg-Marquardt crawls along it.
constexpr double kFunctionTolerance = 1e-7;
// The screen's winner continues this many iterations at most: at large
// accelerations Levenberg-Marquardt crawls along the valley of v and a, and
// the iterations beyond moved the acceleration sweep's medians by less than
// 1 deg (rho 0-30) at twice the time.
constexpr int kContinueIterations = 20;
// The joint refinement's starts merge within this [deg] (celc_ml's kMergeDeg).
constexpr double kMergeDeg = 1.0;

/// x = (v, a) minimising the weighted sum of w_i (a_i^T x)^2 with |v| = 1.
bool weightedSolve(const std::vector<AccRow>& rows, const std::vector<double>& w, bool with_acceleration, Vec6& x,
                   Mat3* schur_out) {
  Mat6 m = Mat6::Zero();
  for (std::size_t i = 0; i < rows.size(); ++i) m.noalias() += w[i] * rows[i].a * rows[i].a.transpose();
  const Mat3 mvv = m.topLeftCorner<3, 3>(), mva = m.topRightCorner<3, 3>(), maa = m.bottomRightCorner<3, 3>();
  Mat3 schur = mvv, k = Mat3::Zero();
  if (with_acceleration) {
    const double ridge = 1e-12 * std::max(maa.trace(), 1e-300);
    k = (maa + ridge * Mat3::Identity()).ldlt().solve(mva.transpose());  // a = -k v
    schur = mvv - mva * k;
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (schur + schur.transpose()));
  if (es.info() != Eigen::Success) return false;
  const Vec3 v = es.eigenvectors().col(0);
  x.head<3>() = v;
  x.tail<3>() = with_acceleration ? Vec3(-k * v) : Vec3::Zero();
  if (schur_out) *schur_out = schur;
  return x.allFinite();
}

/// Geometric residuals of the rows at x.
std::vector<double> residuals(const std::vector<AccRow>& rows, const Vec6& x) {
  std::vector<double> r(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double n = (rows[i].N * x).norm();
    r[i] = n > 1e-300 ? rows[i].a.dot(x) / n : 0.0;
  }
  return r;
}

double robustScale(const std::vector<double>& r) {
  std::vector<double> a(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) a[i] = std::abs(r[i]);
  if (a.empty()) return 0.0;
  auto mid = a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2);
  std::nth_element(a.begin(), mid, a.end());
  return 1.4826 * *mid;
}

/// Huber's cost of the residuals at scale `scale` (threshold k scales).
double huberCost(const std::vector<double>& r, double scale, double k) {
  const double c = k * scale;
  double sum = 0.0;
  for (double e : r) sum += std::abs(e) <= c ? 0.5 * e * e : c * (std::abs(e) - 0.5 * c);
  return sum;
}

struct Fit {
  Vec6 x = Vec6::Zero();
  Mat3 schur = Mat3::Zero();
  double scale = 0.0, cost = 0.0;
  int iterations = 0;
  bool ok = false;
};

/// IRLS from x0: weights Huber(r / scale) / |N x|^2 at a fixed scale (the
/// same for the fits with and without a, so that their costs compare); the
/// end point is the lowest Huber cost met.
Fit irls(const std::vector<AccRow>& rows, Vec6 x, bool with_acceleration, const LinearOptions& opt, double scale) {
  Fit fit;
  fit.x = x;
  fit.scale = scale;
  fit.cost = huberCost(residuals(rows, x), scale, opt.huber_k);
  std::vector<double> w(rows.size());
  for (int it = 0; it < kMaxIterations; ++it) {
    const std::vector<double> r = residuals(rows, x);
    const double c = opt.huber_k * scale;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double n2 = (rows[i].N * x).squaredNorm();
      const double huber = std::abs(r[i]) <= c ? 1.0 : c / std::abs(r[i]);
      w[i] = n2 > 1e-300 ? huber / n2 : 0.0;
    }
    Vec6 next;
    Mat3 schur;
    if (!weightedSolve(rows, w, with_acceleration, next, &schur)) break;
    if (next.head<3>().dot(x.head<3>()) < 0.0) next = -next;
    const double moved = std::acos(std::clamp(next.head<3>().dot(x.head<3>()), -1.0, 1.0));
    x = next;
    fit.iterations = it + 1;
    // Each step's weights are the last one's: keep the lowest robust cost seen.
    const double cost = huberCost(residuals(rows, x), scale, opt.huber_k);
    if (cost < fit.cost || fit.iterations == 1) {
      if (cost < fit.cost || fit.schur.isZero()) fit.schur = schur;
      if (cost < fit.cost) fit.x = x, fit.cost = cost;
    }
    if (moved < 1e-3 * opt.tolerance) break;
  }
  fit.ok = true;
  return fit;
}


/// The linear stage: (v, a) of the accelerating IRLS (|v| = 1, v's sign
/// CELC's), or false when the rows cannot fix it.
bool linearAcceleration(const WindowObservations& obs, const MotionModel& motion, const SolverResult& celc,
                        const LinearOptions& opt, const WindowFrames& frames, std::uint64_t row_seed, Vec6& out) {
  const std::vector<int> usable = usableClusters(obs, opt.min_cluster_events);
  std::vector<size_t> sizes;
  for (int c : usable) sizes.push_back(obs.clusters[c].size());
  const size_t max_rows = opt.max_rows > 0 ? std::min(static_cast<std::size_t>(opt.max_rows), kMaxRows) : kMaxRows;
  const std::vector<size_t> quota = rowQuota(sizes, max_rows, opt.balance_clusters);
  const double t_ref = motion.referenceTime();
  auto q = [&](double t) { return 0.5 * (t - t_ref) * (t - t_ref); };
  std::vector<AccRow> rows;
  for (size_t ci = 0; ci < usable.size(); ++ci) {
    const ClusterObservation& cl = obs.clusters[usable[ci]];
    const ClusterFrame& frame = frames[usable[ci]];
    const double qs = q(cl.l1.t), qe = q(cl.l3.t);
    for (size_t k : sampleIndices(cl.size(), quota[ci], row_seed + ci)) {
      if (!cl.bearings[k].allFinite() || !std::isfinite(cl.times[k])) continue;
      Mat3 rk, pk;
      motion.pose(cl.times[k], rk, pk);
      const Mat3 b_v = transferMatrix(frame, pk);
      const double qk = q(cl.times[k]);
      const Mat3 b_a = (qe - qk) * frame.m1 * frame.m3.transpose() - (qs - qk) * frame.m3 * frame.m1.transpose();
      const Vec3 fp = rk * cl.bearings[k];
      AccRow row;
      row.a << b_v.transpose() * fp, b_a.transpose() * fp;
      const Eigen::Matrix<double, 2, 3> rt = rk.transpose().topRows<2>();
      row.N << rt * b_v, rt * b_a;
      if (row.a.allFinite() && row.N.allFinite()) rows.push_back(row);
    }
  }
  if (rows.size() < 12 || !celc.ok()) return false;
  Vec6 x0 = Vec6::Zero();
  x0.head<3>() = celc.v.normalized();
  const double scale0 = std::max(robustScale(residuals(rows, x0)), 1e-12);
  // From celc's v with a = 0 (the joint refinement's other start, celc_ml's
  // answer, has searched the sphere for v's basin already).
  const Fit accelerating = irls(rows, x0, true, opt, scale0);
  if (!accelerating.ok || !accelerating.x.allFinite() || !(accelerating.x.head<3>().norm() > 0.0)) return false;
  out = accelerating.x / accelerating.x.head<3>().norm();
  if (out.head<3>().dot(celc.v) < 0.0) out = -out;
  return true;
}

}  // namespace

SolverResult solveCelcAcc(const WindowObservations& obs, const MotionModel& motion, const SolverResult& celc,
                          const SolverResult& ml, const MlEnd& ml_end, const SolverOptions& options,
                          const WindowFrames& frames, std::uint64_t row_seed, std::uint64_t event_seed) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, options.linear, result)) return result;
  const AccOptions& acc = options.acc;
  // celc's time is inside celc_ml's (its start).
  const double before_us = ml.time_us;
  // The constant-velocity answer (celc_ml's), with the reason it stands.
  auto constantVelocity = [&](Degeneracy reason, const std::string& why) {
    SolverResult r = ml;
    if (r.ok()) {
      r.degeneracy = reason;
      r.message = why + ": celc_ml's constant-velocity answer";
    }
    r.time_us = before_us + microsecondsSince(start);
    return r;
  };
  if (!ml.ok()) return constantVelocity(Degeneracy::None, "");
  const int lines = static_cast<int>(frames.clusters().size());
  if (lines < acc.min_lines)
    return constantVelocity(Degeneracy::AccelerationUnobservable,
                            std::to_string(lines) + " lines, fewer than the " + std::to_string(acc.min_lines) +
                                " that fix an acceleration");
  JointProblem problem(obs, motion, frames, options.ml.max_events, options.refine.balance_clusters, event_seed,
                       options.refine.huber_px, true);
  if (problem.events() < 12 || static_cast<int>(problem.clusters()) < acc.min_lines)
    return constantVelocity(Degeneracy::AccelerationUnobservable,
                            std::to_string(problem.events()) + " events on " + std::to_string(problem.clusters()) +
                                " lines, too few to fix an acceleration");
  const int iterations = options.refine.max_iterations;
  const double tolerance = std::max(options.refine.function_tolerance, kFunctionTolerance);
  // The starts: celc_ml's answer with a = 0 and its lines (with its Huber
  // threshold: the same events), or, where celc_ml hands over none, with the
  // fitted lines; the linear (v, a) with the fitted lines. Each is refined
  // ml.start_iterations iterations (a start that comes within kMergeDeg of
  // an earlier end point, in v and in every line, stops: it would end
  // there), and the lowest cost continues (kContinueIterations at most).
  // Without celc_ml's threshold, the first end point sets it as celc_ml's
  // does (MlOptions::huber_scale).
  std::vector<JointProblem::State> starts;
  const bool handed = ml_end.valid && ml_end.m1.size() == problem.clusters() && ml_end.huber_px > 0.0;
  JointProblem::State from_ml = problem.start(ml.v);
  if (handed) {
    from_ml.m1 = ml_end.m1;
    from_ml.m3 = ml_end.m3;
    starts.push_back(from_ml);
    problem.setHuber(ml_end.huber_px);
  }
  Vec6 linear;
  if (linearAcceleration(obs, motion, celc, options.linear, frames, row_seed, linear))
    starts.push_back(problem.start(linear.head<3>(), linear.tail<3>()));
  if (!handed) starts.push_back(problem.start(ml.v));
  const int screen_iterations =
      options.ml.start_iterations > 0 ? std::min(options.ml.start_iterations, iterations) : iterations;
  JointProblem::Result best;
  std::vector<JointProblem::State> ends;
  bool threshold_set = handed;
  for (const JointProblem::State& s : starts) {
    JointProblem::Result r = problem.refine(s, screen_iterations, tolerance, 1, ends, kMergeDeg * M_PI / 180.0);
    if (!r.ok || r.merged) continue;
    if (!threshold_set && options.ml.huber_scale > 0.0) {
      threshold_set = true;
      const double scaled = options.ml.huber_scale * problem.robustScale(r.state);
      if (scaled > options.refine.huber_px) {
        problem.setHuber(scaled);
        r = problem.refine(r.state, screen_iterations, tolerance);
        if (!r.ok) continue;
      }
    }
    ends.push_back(r.state);
    if (!best.ok || r.cost < best.cost) best = std::move(r);
  }
  if (best.ok && best.iterations >= screen_iterations && screen_iterations < iterations) {
    JointProblem::Result rest = problem.refine(best.state, std::min(iterations, kContinueIterations), tolerance);
    if (rest.ok) {
      rest.iterations += best.iterations;
      best = std::move(rest);
    }
  }
  if (!best.ok) return constantVelocity(Degeneracy::None, "the accelerating refinement failed");
  // a with the sign of celc_ml's v, for the constant-velocity answers.
  const Vec3 a_along_ml = best.state.v.dot(ml.v) < 0.0 ? Vec3(-best.state.a) : best.state.a;
  // The test's C_0: celc_ml's answer refined on this problem under the
  // constant-velocity model (the answer without a; from celc_ml's lines a
  // few iterations).
  const JointProblem::Result constant = problem.refineConstantVelocity(from_ml, iterations, tolerance);
  // a's covariance with the lines and v eliminated, the residuals' robust
  // scale as the noise's.
  const double scale = problem.robustScale(best.state);
  const Eigen::MatrixXd info = problem.information(best.state);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(info);
  double sigma_a = INFINITY;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(5, 5, NAN);
  if (es.info() == Eigen::Success && es.eigenvalues()(0) > 1e-12 * std::max(es.eigenvalues()(4), 1e-300)) {
    cov = scale * scale * es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() *
          es.eigenvectors().transpose();
    const Mat3 cov_a = cov.bottomRightCorner<3, 3>();
    const Eigen::SelfAdjointEigenSolver<Mat3> ea(cov_a);
    sigma_a = std::sqrt(std::max(0.0, ea.eigenvalues()(2)));
  }
  double reach = 0.0;  // the longest |t - t_ref| [s]
  for (int c : frames.clusters())
    for (double t : obs.clusters[c].times)
      if (std::isfinite(t)) reach = std::max(reach, std::abs(t - motion.referenceTime()));
  char text[240];
  if (!(sigma_a * reach <= acc.max_sigma)) {
    std::snprintf(text, sizeof text,
                  "acceleration not observable: its std times the window's reach, %.3g, above %g", sigma_a * reach,
                  acc.max_sigma);
    SolverResult r = constantVelocity(Degeneracy::AccelerationUnobservable, text);
    r.acceleration = a_along_ml;
    return r;
  }
  const double lr = constant.ok ? 2.0 * (constant.cost - best.cost) / std::max(scale * scale, 1e-300) : INFINITY;
  if (!(lr > acc.test_chi2)) {
    std::snprintf(text, sizeof text, "no acceleration seen (likelihood ratio %.3g <= %g)", lr, acc.test_chi2);
    SolverResult r = constantVelocity(Degeneracy::None, text);
    r.acceleration = a_along_ml;
    return r;
  }
  result.status = SolveStatus::Ok;
  result.acceleration_seen = true;
  result.v = best.state.v;
  result.acceleration = best.state.a;
  SignDecision sign;
  if (options.linear.resolve_sign) {
    sign = resolveSign(obs, motion, result.v, &result.acceleration, frames);
    result.v *= static_cast<double>(sign.sign);
    result.acceleration *= static_cast<double>(sign.sign);
  }
  result.sign_margin = sign.margin * sign.sign;
  result.iterations = best.iterations;
  result.rows_used = best.events;
  result.residual_px = scale;
  // The direction's spread: v's tangent block of the covariance.
  result.sigma_deg = std::sqrt(std::max(0.0, cov.topLeftCorner<2, 2>().trace())) * 180.0 / M_PI;
  if (!std::isfinite(result.sigma_deg)) result.sigma_deg = INFINITY;
  std::snprintf(text, sizeof text, "acceleration seen (likelihood ratio %.3g), |a|/|v| = %.3g 1/s", lr,
                result.acceleration.norm());
  result.message = text;
  result.time_us = before_us + microsecondsSince(start);
  return result;
}

}  // namespace celc::detail
