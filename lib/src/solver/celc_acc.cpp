// CELC with a constant acceleration (celc_acc.hpp).
#include "celc_acc.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
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


/// celc_ml's constant-velocity answer `ml` as celc_acc's, with the reason it
/// stands (where ml is ok), and celc_acc's time, time_us [us].
SolverResult constantVelocity(const SolverResult& ml, Degeneracy reason, const std::string& why, double time_us) {
  SolverResult r = ml;
  if (r.ok()) {
    r.degeneracy = reason;
    r.message = why + ": celc_ml's constant-velocity answer";
  }
  r.time_us = time_us;
  return r;
}

/// The joint refinement's starts and celc_ml's answer as a state.
struct AccStarts {
  std::vector<JointProblem::State> states;
  JointProblem::State from_ml;  ///< celc_ml's v with a = 0, and its lines where handed over
  bool handed = false;          ///< celc_ml handed over its lines and its Huber threshold
};

/// The starts: celc_ml's answer with a = 0 and its lines (with its Huber
/// threshold, which the problem takes: the same events), or, where celc_ml
/// hands over none, with the fitted lines; the linear (v, a) `linear` (null:
/// none) with the fitted lines; celc_ml's v with the accelerometer's a
/// (over a speed) `a_measured` (null: none) with the fitted lines.
AccStarts accStarts(JointProblem& problem, const SolverResult& ml, const MlEnd& ml_end, const Vec6* linear,
                    const Vec3* a_measured) {
  AccStarts s;
  s.handed = ml_end.valid && ml_end.m1.size() == problem.clusters() && ml_end.huber_px > 0.0;
  s.from_ml = problem.start(ml.v);
  if (s.handed) {
    s.from_ml.m1 = ml_end.m1;
    s.from_ml.m3 = ml_end.m3;
    s.states.push_back(s.from_ml);
    problem.setLoss(RobustLoss::huber(ml_end.huber_px));
  }
  if (linear) s.states.push_back(problem.start(linear->head<3>(), linear->tail<3>()));
  if (!s.handed) s.states.push_back(problem.start(ml.v));
  if (a_measured) s.states.push_back(problem.start(ml.v, *a_measured));
  return s;
}

/// The screen: each start refined ml.start_iterations iterations (a start
/// that comes within kMergeDeg of an earlier end point, in v and in every
/// line, stops: it would end there), and the lowest cost continues
/// (kContinueIterations at most). Without celc_ml's threshold, the first end
/// point sets the problem's as celc_ml's does (MlOptions::huber_scale).
/// Returns the lowest end point, not ok where there is none.
JointProblem::Result screenAccStarts(JointProblem& problem, const AccStarts& starts, int iterations,
                                     double tolerance, const SolverOptions& options) {
  const int screen_iterations =
      options.ml.start_iterations > 0 ? std::min(options.ml.start_iterations, iterations) : iterations;
  JointProblem::Result best;
  std::vector<JointProblem::State> ends;
  bool threshold_set = starts.handed;
  for (const JointProblem::State& s : starts.states) {
    JointProblem::Result r = problem.refine(s, screen_iterations, tolerance, 1, ends, kMergeDeg * M_PI / 180.0);
    if (!r.ok || r.merged) continue;
    if (!threshold_set && options.ml.huber_scale > 0.0) {
      threshold_set = true;
      const double scaled = options.ml.huber_scale * problem.robustScale(r.state);
      if (scaled > options.refine.huber_px) {
        problem.setLoss(RobustLoss::huber(scaled));
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
  return best;
}

/// The end point's spread: the residuals' robust scale [px] as the noise's;
/// the covariance of (v's tangent, a) with the lines eliminated, from the
/// Fisher information with independent events (cov) and from the clusters'
/// scores (robust_cov, JointProblem::clusterRobustCovariance), NaN where
/// singular; a's largest std [1/s] over both (infinite where cov is NaN);
/// and the cluster-robust Wald statistic a^T robust_cov_aa^-1 a (NaN where
/// robust_cov is).
struct AccSpread {
  double scale = 0.0;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(5, 5, NAN);
  Eigen::MatrixXd robust_cov = Eigen::MatrixXd::Constant(5, 5, NAN);
  double sigma_a = INFINITY;
  double robust_wald = NAN;
};

/// The largest standard deviation of a 3 x 3 covariance [its unit]; NaN
/// where it is not finite.
double largestStd(const Mat3& cov) {
  if (!cov.allFinite()) return NAN;
  const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  return std::sqrt(std::max(0.0, es.eigenvalues()(2)));
}

/// The spread at s (AccSpread).
AccSpread accelerationSpread(const JointProblem& problem, const JointProblem::State& s) {
  AccSpread out;
  out.scale = problem.robustScale(s);
  const Eigen::MatrixXd info = problem.information(s);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(info);
  if (es.info() == Eigen::Success && es.eigenvalues()(0) > 1e-12 * std::max(es.eigenvalues()(4), 1e-300)) {
    out.cov = out.scale * out.scale * es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() *
              es.eigenvectors().transpose();
    out.sigma_a = largestStd(out.cov.bottomRightCorner<3, 3>());
  }
  out.robust_cov = problem.clusterRobustCovariance(s);
  const Mat3 robust_aa = out.robust_cov.bottomRightCorner<3, 3>();
  const double robust_sigma_a = largestStd(robust_aa);
  if (std::isfinite(robust_sigma_a)) out.sigma_a = std::max(out.sigma_a, robust_sigma_a);
  if (robust_aa.allFinite()) {
    // a^T C^-1 a over C's eigenvectors; a direction with no spread (noise-free
    // clusters) and a part of a along it makes the statistic infinite.
    const Eigen::SelfAdjointEigenSolver<Mat3> er(robust_aa);
    const double tiny = 1e-15 * std::max(er.eigenvalues()(2), 1e-300);
    out.robust_wald = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double along = er.eigenvectors().col(i).dot(s.a);
      out.robust_wald += er.eigenvalues()(i) > tiny ? along * along / er.eigenvalues()(i)
                                                    : (along != 0.0 ? INFINITY : 0.0);
    }
  }
  return out;
}

/// The camera's mean acceleration over its speed [1/s] in the reference
/// frame over [t0, t1] at the end point (v, a), what the accelerometer
/// measures: with p(t) = P(t) v + q(t) a, p'' = a where the velocity is
/// constant in the reference frame (P = tau I); where it is constant in the
/// body frame, P' = R(t) and p''(t) = R(t) (w(t) x v) + a, whose mean over
/// [t0, t1] is a + (R(t1) v - R(t0) v) / (t1 - t0), v unit.
Vec3 meanAcceleration(const Vec3& v, const Vec3& a, const MotionModel& motion, double t0, double t1) {
  if (motion.velocityFrame() == VelocityFrame::Reference || !(t1 > t0)) return a;
  const Vec3 u = v.normalized();
  return a + (motion.rotate(t1, u) - motion.rotate(t0, u)) / (t1 - t0);
}

/// The accelerometer against an accelerating end point (AccOptions::accelerometer_chi2):
/// the statistic and the speed s [m/s] that fits a (over the speed [1/s],
/// along v = the camera's velocity) to the measured a_m [m/s^2] best. c_aa
/// is a's covariance [1/s^2] (NaN: taken as 0).
struct AccelerometerAgreement {
  double chi2 = NAN;
  double speed = NAN;
};

AccelerometerAgreement accelerometerAgreement(const MeasuredAcceleration& m, const Vec3& a, const Mat3& c_aa) {
  AccelerometerAgreement out;
  if (!a.allFinite()) return out;
  const double a2 = a.squaredNorm();
  out.speed = a2 > 0.0 ? std::max(0.0, m.a.dot(a) / a2) : 0.0;
  const Vec3 r = m.a - out.speed * a;
  Mat3 cov = std::max(m.sigma * m.sigma, 1e-12) * Mat3::Identity();
  if (c_aa.allFinite()) cov += out.speed * out.speed * c_aa;
  out.chi2 = r.dot(cov.ldlt().solve(r));
  return out;
}

/// a's covariance at the spread: the Fisher or the cluster-robust block,
/// whichever is larger (trace), NaN where neither is finite.
Mat3 accelerationCovariance(const AccSpread& spread) {
  const Mat3 fisher = spread.cov.bottomRightCorner<3, 3>(), robust = spread.robust_cov.bottomRightCorner<3, 3>();
  if (!robust.allFinite()) return fisher;
  if (!fisher.allFinite()) return robust;
  return robust.trace() > fisher.trace() ? robust : fisher;
}

/// The accelerating answer from the end point `best`: v and a (times the
/// sign decided, judgeEnd), the spread of v's tangent block as
/// sigma_deg, the robust scale as the residual, the likelihood ratio lr in
/// the message; its time is not set.
SolverResult acceleratingAnswer(const JointProblem::Result& best, const AccSpread& spread, double lr,
                                const SignDecision& sign) {
  SolverResult result;
  result.status = SolveStatus::Ok;
  result.acceleration_seen = true;
  result.v = static_cast<double>(sign.sign) * best.state.v;
  result.acceleration = static_cast<double>(sign.sign) * best.state.a;
  result.sign_margin = sign.margin * sign.sign;
  result.iterations = best.iterations;
  result.rows_used = best.events;
  result.residual_px = spread.scale;
  // The larger of the Fisher and the cluster-robust spreads of v's tangent.
  double var_v = spread.cov.topLeftCorner<2, 2>().trace();
  const double robust_var_v = spread.robust_cov.topLeftCorner<2, 2>().trace();
  if (std::isfinite(robust_var_v)) var_v = std::max(var_v, robust_var_v);
  result.sigma_deg = std::sqrt(std::max(0.0, var_v)) * 180.0 / M_PI;
  if (!std::isfinite(result.sigma_deg)) result.sigma_deg = INFINITY;
  char text[240];
  std::snprintf(text, sizeof text,
                "acceleration seen (likelihood ratio %.3g, cluster-robust Wald %.3g), |a|/|v| = %.3g 1/s", lr,
                spread.robust_wald, result.acceleration.norm());
  result.message = text;
  return result;
}

/// What the tests make of an accelerating end point: the acceleration is
/// not observable, not seen (the likelihood ratio against the
/// constant-velocity cost C_0 and the cluster-robust Wald statistic, both
/// against test_chi2), contradicted by the accelerometer, or seen.
struct AccJudgement {
  enum class Verdict { Unobservable, NotSeen, Contradicted, Seen };
  Verdict verdict = Verdict::NotSeen;
  Degeneracy reason = Degeneracy::None;
  std::string why;             ///< the message of a constant-velocity answer
  Vec3 a_along_ml;             ///< a with the sign of celc_ml's v
  SignDecision sign;           ///< the sign of (v, a): by cheirality with resolve_sign, else celc_ml's
  AccSpread spread;
  double lr = NAN;             ///< the likelihood ratio
  AccelerometerAgreement agreement;  ///< chi2 NaN without accelerometer
  /// The accelerometer's reading stands out of its noise
  /// (AccOptions::accelerometer_start_sigma): only then does the agreement
  /// fix a speed.
  bool reading_significant = false;
};

/// The window an accelerating end point is judged on.
struct AccWindow {
  const WindowObservations& obs;
  const MotionModel& motion;
  const WindowFrames& frames;
  double reach;  ///< the usable clusters' events' longest |t - t_ref| [s]
};

AccJudgement judgeEnd(const JointProblem& problem, const JointProblem::Result& end,
                      const JointProblem::Result& constant, const SolverResult& ml, const AccWindow& w,
                      const SolverOptions& options) {
  const AccOptions& acc = options.acc;
  const double reach = w.reach;
  AccJudgement j;
  j.a_along_ml = end.state.v.dot(ml.v) < 0.0 ? Vec3(-end.state.a) : end.state.a;
  j.spread = accelerationSpread(problem, end.state);
  char text[240];
  if (!(j.spread.sigma_a * reach <= acc.max_sigma)) {
    j.verdict = AccJudgement::Verdict::Unobservable;
    j.reason = Degeneracy::AccelerationUnobservable;
    std::snprintf(text, sizeof text, "acceleration not observable: its std times the window's reach, %.3g, above %g",
                  j.spread.sigma_a * reach, acc.max_sigma);
    j.why = text;
    return j;
  }
  const double scale2 = std::max(j.spread.scale * j.spread.scale, 1e-300);
  j.lr = constant.ok ? 2.0 * (constant.cost - end.cost) / scale2 : INFINITY;
  // Seen only where both tests pass: the likelihood ratio (independent
  // events) and the cluster-robust Wald statistic (clusters as samples;
  // NaN with too few clusters, where the ratio decides alone).
  if (!(j.lr > acc.test_chi2) || j.spread.robust_wald <= acc.test_chi2) {
    std::snprintf(text, sizeof text,
                  "no acceleration seen (likelihood ratio %.3g, cluster-robust Wald %.3g; both must exceed %g)", j.lr,
                  j.spread.robust_wald, acc.test_chi2);
    j.why = text;
    return j;
  }
  j.sign.sign = end.state.v.dot(ml.v) < 0.0 ? -1 : 1;
  if (options.linear.resolve_sign) j.sign = resolveSign(w.obs, w.motion, end.state.v, &end.state.a, w.frames);
  const MeasuredAcceleration& measured = w.obs.accelerometer;
  if (measured.valid) {
    const double sign = static_cast<double>(j.sign.sign);
    const Vec3 a = meanAcceleration(sign * end.state.v, sign * end.state.a, w.motion, measured.t0, measured.t1);
    j.agreement = accelerometerAgreement(measured, a, accelerationCovariance(j.spread));
    j.reading_significant = measured.a.norm() >= acc.accelerometer_start_sigma * measured.sigma;
    if (!(j.agreement.chi2 <= acc.accelerometer_chi2)) {
      j.verdict = AccJudgement::Verdict::Contradicted;
      std::snprintf(text, sizeof text,
                    "the accelerometer contradicts the acceleration seen (likelihood ratio %.3g; accelerometer "
                    "chi2 %.3g above %g, |a_m| = %.3g m/s^2)",
                    j.lr, j.agreement.chi2, acc.accelerometer_chi2, measured.a.norm());
      j.why = text;
      return j;
    }
  }
  j.verdict = AccJudgement::Verdict::Seen;
  return j;
}

/// The accelerating answer at `end` with its judgement, its time set.
SolverResult acceptedAnswer(const JointProblem::Result& end, const AccJudgement& judged, double time_us) {
  SolverResult result = acceleratingAnswer(end, judged.spread, judged.lr, judged.sign);
  char text[160] = "";
  if (std::isfinite(judged.agreement.chi2) && judged.reading_significant && judged.agreement.speed > 0.0)
    std::snprintf(text, sizeof text, "; the accelerometer agrees (chi2 %.3g), |v| about %.3g m/s",
                  judged.agreement.chi2, judged.agreement.speed);
  else if (std::isfinite(judged.agreement.chi2))
    std::snprintf(text, sizeof text, "; the accelerometer reads no acceleration beyond its noise (chi2 %.3g)",
                  judged.agreement.chi2);
  result.message += text;
  result.time_us = time_us;
  return result;
}

}  // namespace

SolverResult solveCelcAcc(const WindowObservations& obs, const MotionModel& motion, const SolverResult& celc,
                          const SolverResult& ml, const MlEnd& ml_end, const SolverOptions& options,
                          const WindowFrames& frames, std::uint64_t row_seed, std::uint64_t event_seed) {
  const auto start = Clock::now();
  SolverResult rejected;
  if (rejectInput(obs, motion, options.linear, rejected)) return rejected;
  const AccOptions& acc = options.acc;
  // celc's time is inside celc_ml's (its start).
  const double before_us = ml.time_us;
  if (!ml.ok()) return constantVelocity(ml, Degeneracy::None, "", before_us + microsecondsSince(start));
  const int lines = static_cast<int>(frames.clusters().size());
  if (lines < acc.min_lines)
    return constantVelocity(ml, Degeneracy::AccelerationUnobservable,
                            std::to_string(lines) + " lines, fewer than the " + std::to_string(acc.min_lines) +
                                " that fix an acceleration",
                            before_us + microsecondsSince(start));
  JointProblem problem(obs, motion, frames, options.ml.max_events, options.refine.balance_clusters, event_seed,
                       options.refine.huber_px, true);
  if (problem.events() < 12 || static_cast<int>(problem.clusters()) < acc.min_lines)
    return constantVelocity(ml, Degeneracy::AccelerationUnobservable,
                            std::to_string(problem.events()) + " events on " + std::to_string(problem.clusters()) +
                                " lines, too few to fix an acceleration",
                            before_us + microsecondsSince(start));
  const int iterations = options.refine.max_iterations;
  const double tolerance = std::max(options.refine.function_tolerance, kFunctionTolerance);
  // The usable clusters' events span [t_first, t_last]; reach is their longest |t - t_ref| [s].
  double t_first = INFINITY, t_last = -INFINITY;
  for (int c : frames.clusters())
    for (double t : obs.clusters[c].times)
      if (std::isfinite(t)) t_first = std::min(t_first, t), t_last = std::max(t_last, t);
  const double t_ref = motion.referenceTime();
  const double reach = t_last >= t_first ? std::max(std::abs(t_first - t_ref), std::abs(t_last - t_ref)) : 0.0;
  Vec6 linear;
  const bool have_linear = linearAcceleration(obs, motion, celc, options.linear, frames, row_seed, linear);
  // The accelerometer's a as a start, over a speed: the linear stage's |a|
  // where there is one, else a velocity change of the velocity's size over the window.
  const MeasuredAcceleration& measured = obs.accelerometer;
  const bool measured_start = measured.valid && measured.a.norm() > 0.0 &&
                              measured.a.norm() >= acc.accelerometer_start_sigma * measured.sigma;
  const double start_rate =
      have_linear && linear.tail<3>().norm() > 0.0 ? linear.tail<3>().norm() : 1.0 / std::max(reach, 1e-3);
  const Vec3 a_measured =
      measured_start ? Vec3(start_rate * measured.a.normalized() -
                            meanAcceleration(ml.v, Vec3::Zero(), motion, measured.t0, measured.t1))
                     : Vec3::Zero();
  const AccStarts starts =
      accStarts(problem, ml, ml_end, have_linear ? &linear : nullptr, measured_start ? &a_measured : nullptr);
  const JointProblem::Result best = screenAccStarts(problem, starts, iterations, tolerance, options);
  if (!best.ok)
    return constantVelocity(ml, Degeneracy::None, "the accelerating refinement failed",
                            before_us + microsecondsSince(start));
  // The test's C_0: celc_ml's answer refined on this problem under the
  // constant-velocity model (the answer without a; from celc_ml's lines a
  // few iterations).
  const JointProblem::Result constant = problem.refineConstantVelocity(starts.from_ml, iterations, tolerance);
  const AccWindow window{obs, motion, frames, reach};
  const AccJudgement judged = judgeEnd(problem, best, constant, ml, window, options);
  if (judged.verdict == AccJudgement::Verdict::Contradicted && measured_start) {
    // The lowest end point contradicts the accelerometer: the end point of
    // its own start, where that one agrees.
    const JointProblem::Result own = problem.refine(starts.states.back(), iterations, tolerance);
    if (own.ok) {
      const AccJudgement second = judgeEnd(problem, own, constant, ml, window, options);
      if (second.verdict == AccJudgement::Verdict::Seen)
        return acceptedAnswer(own, second, before_us + microsecondsSince(start));
    }
  }
  if (judged.verdict != AccJudgement::Verdict::Seen) {
    SolverResult r = constantVelocity(ml, judged.reason, judged.why, before_us + microsecondsSince(start));
    r.acceleration = judged.a_along_ml;
    // Refused by the accelerometer: the events showed an acceleration that
    // is not the camera's, so neither model explains them; the two answers'
    // angle bounds sigma_deg from below.
    if (judged.verdict == AccJudgement::Verdict::Contradicted && r.ok())
      r.sigma_floor_deg =
          angleBetween(ml.v, static_cast<double>(judged.sign.sign) * best.state.v) * 180.0 / M_PI;
    return r;
  }
  return acceptedAnswer(best, judged, before_us + microsecondsSince(start));
}

}  // namespace celc::detail
