// Method `npt`: Gao et al., CVPR 2024, N-point linear solver + velocity averaging.
#include "celc/solver/npt.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace celc {

std::string toString(NptTimeOrigin origin) {
  return origin == NptTimeOrigin::Centre ? "centre" : "first_event";
}

std::string toString(NptLineNormalisation normalisation) {
  return normalisation == NptLineNormalisation::Vector ? "vector" : "moment";
}

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// s(t) with c(t) = s(t) v: trace(P(t)) / 3 (exactly tau for P = tau I).
double displacementScale(const Mat3& P) { return P.trace() / 3.0; }

// The first and last finite times of a list.
void extendRange(const std::vector<double>& times, double& first, double& last) {
  for (double t : times)
    if (std::isfinite(t)) first = std::min(first, t), last = std::max(last, t);
}

double originOf(double first, double last, NptTimeOrigin origin) {
  if (!(first <= last)) return 0.0;  // no finite time
  return origin == NptTimeOrigin::Centre ? 0.5 * (first + last) : first;
}

}  // namespace

double nptTimeOrigin(const WindowObservations& obs, NptTimeOrigin origin) {
  double first = INFINITY, last = -INFINITY;
  for (const auto& c : obs.clusters) extendRange(c.times, first, last);
  return originOf(first, last, origin);
}

NptLineSolution solveNptLine(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             const MotionModel& motion, const NptOptions& opt) {
  double first = INFINITY, last = -INFINITY;
  extendRange(times, first, last);
  return solveNptLine(times, bearings, motion, opt, originOf(first, last, opt.time_origin));
}

NptLineSolution solveNptLine(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             const MotionModel& motion, const NptOptions& opt, double t0) {
  NptLineSolution out;
  // The camera centre relative to the one at t0: (s(t) - s(t0)) v.
  const double s0 = displacementScale(motion.positionMatrix(t0));
  // Normal matrix of the rows [s f'^T, f'^T]: its eigenvectors are the right
  // singular vectors of the stacked rows (eigenvalues = squared singular values).
  Mat6 G = Mat6::Zero();
  const size_t n = std::min(times.size(), bearings.size());
  for (size_t k = 0; k < n; ++k) {
    if (!std::isfinite(times[k]) || !bearings[k].allFinite() || !(bearings[k].norm() > 0.0))
      continue;
    Mat3 R, P;
    motion.pose(times[k], R, P);
    const Vec3 fp = R * bearings[k].normalized();
    Vec6 row;
    row << (displacementScale(P) - s0) * fp, fp;
    if (!row.allFinite()) continue;
    // The upper triangle only: G is symmetric (the lower one is copied below).
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i <= j; ++i) G(i, j) += row(i) * row(j);
    ++out.events;
  }
  G.triangularView<Eigen::StrictlyLower>() = G.transpose();
  if (out.events < opt.min_line_events) return out;
  const Eigen::SelfAdjointEigenSolver<Mat6> es(G);
  if (es.info() != Eigen::Success) return out;
  const Vec6 ev = es.eigenvalues().cwiseMax(0.0);
  out.sigma_min = std::sqrt(ev(0));
  out.sigma_second = std::sqrt(ev(1));
  if (!(ev(5) > 0.0) || out.sigma_second < opt.min_line_sigma_ratio * std::sqrt(ev(5))) return out;
  out.x = es.eigenvectors().col(0).normalized();
  const Vec3 a = out.x.head<3>(), m = out.x.tail<3>();
  const Vec3 mxa = m.cross(a);
  // No parallax: a = d x v ~ 0 (v = 0 or v along d), or a parallel to m (v in
  // the plane of the line and the camera centre: the image line does not move;
  // with v = 0 the nullspace is [alpha m; beta m]); or a line through the centre.
  if (!(m.norm() > 1e-14) || !(a.norm() > 1e-9 * m.norm()) ||
      !(mxa.norm() > 1e-6 * m.norm() * a.norm()))
    return out;
  if (opt.line_normalisation == NptLineNormalisation::Moment) out.x /= m.norm();
  const Vec3 d = mxa.normalized();
  out.direction = d;
  out.partial_velocity = out.x.head<3>().cross(d);
  const Vec3 e2 = -m.normalized();  // the same for either scaling
  const Vec3 e3 = d.cross(e2);
  const double uy = out.partial_velocity.dot(e2), uz = out.partial_velocity.dot(e3);
  out.averaging_row = uz * e2 - uy * e3;
  out.ok = out.averaging_row.allFinite();
  return out;
}

SolverResult solveNpt(const WindowObservations& obs, const MotionModel& motion,
                      const NptOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  SolverResult r;
  auto done = [&]() -> SolverResult {
    r.time_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                    .count();
    return r;
  };
  if (const std::string err = opt.validate(); !err.empty()) {
    r.status = SolveStatus::InvalidInput;
    r.message = "options: " + err;
    return done();
  }
  if (!motion.rotation(motion.referenceTime()).allFinite()) {
    r.status = SolveStatus::InvalidInput;
    r.message = "angular velocity is not finite";
    return done();
  }
  Mat3 H = Mat3::Zero();  // sum of row row^T of the averaging stage
  int lines = 0;
  const double t0 = nptTimeOrigin(obs, opt.time_origin);
  for (const auto& c : obs.clusters) {
    const NptLineSolution line = solveNptLine(c.times, c.bearings, motion, opt, t0);
    r.rows_used += line.events;
    if (!line.ok) continue;
    H += line.averaging_row * line.averaging_row.transpose();
    ++lines;
  }
  if (lines < opt.min_lines) {
    r.status = SolveStatus::Degenerate;
    r.degeneracy = Degeneracy::TooFewClusters;
    r.message = std::to_string(lines) + " lines with a partial velocity, need " +
                std::to_string(opt.min_lines);
    return done();
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> es(H);
  const Vec3 ev = es.eigenvalues().cwiseMax(0.0);
  r.sigma_min = std::sqrt(ev(0));
  r.sigma_second = std::sqrt(ev(1));
  r.iterations = 1;
  if (es.info() != Eigen::Success || !(r.sigma_second > 1e-12 * std::sqrt(ev(2))) ||
      r.sigma_min > opt.max_sigma_ratio * r.sigma_second) {
    r.status = SolveStatus::Degenerate;
    r.degeneracy = Degeneracy::NullspaceNotUnique;
    r.message = "partial velocities do not fix a unique direction";
    return done();
  }
  r.v = es.eigenvectors().col(0).normalized();
  r.status = r.v.allFinite() ? SolveStatus::Ok : SolveStatus::Failed;
  return done();
}

}  // namespace celc
