// The window checks: usable clusters and the parallax test.
#include "window_checks.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "linear_method.hpp"
#include "sampling.hpp"
#include "stopwatch.hpp"

namespace celc {

namespace detail {

std::vector<int> usableClusters(const WindowObservations& obs, int min_events) {
  std::vector<int> idx;
  for (size_t c = 0; c < obs.clusters.size(); ++c) {
    const auto& cl = obs.clusters[c];
    if (static_cast<int>(cl.size()) < min_events || cl.bearings.size() != cl.times.size()) continue;
    if (!cl.has_lines) continue;
    if (!cl.l1.normal.allFinite() || !cl.l3.normal.allFinite()) continue;
    if (!(cl.l1.normal.norm() > 0.0) || !(cl.l3.normal.norm() > 0.0)) continue;
    if (!(cl.l3.t > cl.l1.t)) continue;
    idx.push_back(static_cast<int>(c));
  }
  return idx;
}

ClusterParallax clusterParallax(const ClusterObservation& c, const MotionModel& motion,
                                double focal_px, int max_events) {
  ClusterParallax out;
  const size_t n = c.size();
  if (n < 8) return out;
  const size_t stride = std::max<size_t>(1, n / static_cast<size_t>(std::max(1, max_events)));
  const double t0 = c.times.front(), t1 = c.times.back();
  const double tm = 0.5 * (t0 + t1), half = std::max(1e-9, 0.5 * (t1 - t0));
  std::vector<Vec3> f;
  std::vector<double> tau;
  for (size_t k = 0; k < n; k += stride) {
    if (!c.bearings[k].allFinite() || !std::isfinite(c.times[k])) continue;
    f.push_back(motion.rotate(c.times[k], c.bearings[k]).normalized());
    tau.push_back((c.times[k] - tm) / half);
  }
  if (f.size() < 8) return out;
  // Static line: plane normal n minimising sum (n . f)^2; moving line: the
  // 6-vector (n0, n1) minimising sum ((n0 + tau n1) . f)^2.
  Mat3 S = Mat3::Zero();
  Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Zero();
  for (size_t k = 0; k < f.size(); ++k) {
    S.noalias() += f[k] * f[k].transpose();
    Eigen::Matrix<double, 6, 1> row;
    row << f[k], tau[k] * f[k];
    M.noalias() += row * row.transpose();
  }
  const Vec3 ns = Eigen::SelfAdjointEigenSolver<Mat3>(S).eigenvectors().col(0);
  const Eigen::Matrix<double, 6, 1> x =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(M).eigenvectors().col(0);
  std::vector<double> rs(f.size()), rm(f.size());
  for (size_t k = 0; k < f.size(); ++k) {
    rs[k] = ns.dot(f[k]);
    const Vec3 nk = x.head<3>() + tau[k] * x.tail<3>();
    const double nn = nk.norm();
    rm[k] = nn > 0.0 ? nk.dot(f[k]) / nn : 0.0;
  }
  out.static_px = 1.4826 * medianAbs(rs) * focal_px;
  out.moving_px = 1.4826 * medianAbs(rm) * focal_px;
  return out;
}

bool windowIsDegenerate(const WindowObservations& obs, const MotionModel& motion,
                        const std::vector<int>& usable, const LinearOptions& opt,
                        bool check_parallax, SolverResult& result) {
  if (static_cast<int>(usable.size()) < opt.min_clusters) {
    result = failure(SolveStatus::Degenerate, Degeneracy::TooFewClusters,
                     std::to_string(usable.size()) + " usable clusters, need " +
                         std::to_string(opt.min_clusters));
    return true;
  }
  if (!check_parallax) return false;
  // The parallax test looks at up to 120 events per cluster.
  constexpr int kParallaxEvents = 120;
  int with_events = 0, with_parallax = 0;
  std::vector<double> ratios;
  for (int c : usable) {
    if (obs.clusters[c].size() < 8) continue;
    ++with_events;
    const auto p = clusterParallax(obs.clusters[c], motion, obs.focal_px, kParallaxEvents);
    if (p.static_px >= opt.min_parallax_px &&
        p.static_px >= opt.min_parallax_ratio * std::max(p.moving_px, 1e-12))
      ++with_parallax;
    if (p.static_px > 0.0 || p.moving_px > 0.0) ratios.push_back(p.static_px / std::max(p.moving_px, 1e-12));
  }
  // The window's parallax: the median ratio over the clusters (reported only).
  double parallax = NAN;
  if (!ratios.empty()) {
    std::sort(ratios.begin(), ratios.end());
    const size_t n = ratios.size();
    parallax = n % 2 ? ratios[n / 2] : 0.5 * (ratios[n / 2 - 1] + ratios[n / 2]);
  }
  result.parallax = parallax;
  if (with_events > 0 && with_parallax < opt.min_clusters) {
    result = failure(SolveStatus::Degenerate, Degeneracy::NoParallax,
                     std::to_string(with_parallax) + " clusters show parallax, need " +
                         std::to_string(opt.min_clusters));
    result.parallax = parallax;
    return true;
  }
  if (static_cast<int>(ratios.size()) >= opt.min_window_parallax_clusters &&
      parallax < opt.min_window_parallax) {
    result = failure(SolveStatus::Degenerate, Degeneracy::NoParallax,
                     "window parallax " + std::to_string(parallax) + " (median over clusters) below " +
                         std::to_string(opt.min_window_parallax));
    result.parallax = parallax;
    return true;
  }
  return false;
}

SolverResult checkWindow(const WindowObservations& obs, const MotionModel& motion,
                         const LinearOptions& opt, bool check_parallax) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, opt, result)) return result;
  const std::vector<int> usable = usableClusters(obs, opt.min_cluster_events);
  if (!windowIsDegenerate(obs, motion, usable, opt, check_parallax, result))
    result.status = SolveStatus::Ok;
  result.n_lines = static_cast<int>(usable.size());
  result.time_us = microsecondsSince(start);
  return result;
}

}  // namespace detail

SolverResult checkWindow(const WindowObservations& obs, const MotionModel& motion,
                         const LinearOptions& options) {
  return detail::checkWindow(obs, motion, options, true);
}

}  // namespace celc
