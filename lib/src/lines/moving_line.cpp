#include "moving_line.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace celc::detail {

DerotatedEvents derotate(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                         const MotionModel* motion) {
  DerotatedEvents out;
  out.g.resize(bearings.size());
  out.z.resize(bearings.size());
  for (std::size_t j = 0; j < bearings.size(); ++j) {
    if (motion) {
      const Mat3 R = motion->rotation(times[j]);
      out.g[j] = R * bearings[j];
      out.z[j] = R.col(2);
    } else {
      out.g[j] = bearings[j];
      out.z[j] = Vec3::UnitZ();
    }
  }
  return out;
}

namespace {
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// min x^T M x over x = (n0, n1) with |n0| = 1: n1 eliminated (ridge lambda on
// it, so that a still line, whose n1 is free along n0, stays well posed), n0
// the smallest eigenvector of the Schur complement.
Vec6 solveConstrained(const Mat6& M) {
  const Mat3 A = M.topLeftCorner<3, 3>(), B = M.topRightCorner<3, 3>();
  Mat3 C = M.bottomRightCorner<3, 3>();
  const double lambda = 1e-9 * (A.trace() + C.trace()) + 1e-300;
  C.diagonal().array() += lambda;
  const Eigen::LDLT<Mat3> Cinv(C);
  const Mat3 S = A - B * Cinv.solve(B.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (S + S.transpose()));
  Vec6 x;
  x.head<3>() = eig.eigenvectors().col(0);
  x.tail<3>() = -Cinv.solve(B.transpose() * x.head<3>());
  return x;
}
}  // namespace

FittedLine fitMovingLine(const std::vector<double>& times, const DerotatedEvents& ev,
                         std::size_t begin, std::size_t end, double t_line, const Mat3& R_line,
                         double focal_px) {
  FittedLine out;
  const std::size_t n = end - begin;
  out.n_events = static_cast<int>(n);
  if (n < 6) return out;  // five degrees of freedom
  out.t_first = times[begin];
  out.t_last = times[end - 1];
  // Time in units of the interval's reach from t_line (conditioning).
  double reach = 0.0;
  for (std::size_t j = begin; j < end; ++j) reach = std::max(reach, std::fabs(times[j] - t_line));
  const double scale = reach > 0.0 ? 1.0 / reach : 0.0;

  // Per event: its time s in those units and the six products of g, so that
  // M = sum w [g g^T, s g g^T; s g g^T, s^2 g g^T] is three weighted sums of them.
  std::vector<double> s(n), weight(n, 1.0), d2(n), abs_residual(n), scratch(n);
  std::vector<std::array<double, 6>> gg(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& g = ev.g[begin + i];
    s[i] = (times[begin + i] - t_line) * scale;
    gg[i] = {g.x() * g.x(), g.x() * g.y(), g.x() * g.z(), g.y() * g.y(), g.y() * g.z(), g.z() * g.z()};
  }
  auto symmetric = [](const std::array<double, 6>& u) {
    Mat3 m;
    m << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
    return m;
  };
  Vec6 x = Vec6::Zero();
  double sigma = 0.0;
  constexpr int kIterations = 6;
  for (int it = 0; it < kIterations; ++it) {
    std::array<double, 6> a{}, b{}, c{};
    for (std::size_t i = 0; i < n; ++i) {
      const double w0 = weight[i], w1 = w0 * s[i], w2 = w1 * s[i];
      for (int k = 0; k < 6; ++k) {
        a[k] += w0 * gg[i][k];
        b[k] += w1 * gg[i][k];
        c[k] += w2 * gg[i][k];
      }
    }
    Mat6 M;
    M.topLeftCorner<3, 3>() = symmetric(a);
    M.topRightCorner<3, 3>() = M.bottomLeftCorner<3, 3>() = symmetric(b);
    M.bottomRightCorner<3, 3>() = symmetric(c);
    x = solveConstrained(M);
    // Pixel distances to the line at each event's time; Huber weights over
    // the squared normaliser turn the algebraic fit into a geometric one.
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 nt = x.head<3>() + s[i] * x.tail<3>();
      d2[i] = std::max(nt.squaredNorm() - std::pow(nt.dot(ev.z[begin + i]), 2), 1e-300);
      abs_residual[i] = std::fabs(focal_px * nt.dot(ev.g[begin + i]) / std::sqrt(d2[i]));
    }
    scratch = abs_residual;  // the median reorders its input
    auto mid = scratch.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(scratch.begin(), mid, scratch.end());
    sigma = 1.4826 * *mid;
    const double k = 1.345 * std::max(sigma, 0.05);
    for (std::size_t i = 0; i < n; ++i) {
      const double r = abs_residual[i];
      weight[i] = (r <= k ? 1.0 : k / r) / d2[i];
    }
  }
  const Vec3 n0 = x.head<3>();
  out.line.normal = (R_line.transpose() * n0).normalized();
  out.line.t = t_line;
  out.rms_px = sigma;
  // Extent along the line at t_line: the events seen from the camera at t_line.
  const Vec3& l = out.line.normal;
  const Vec2 dir = Vec2(-l.y(), l.x()).normalized();
  double lo = 1e300, hi = -1e300;
  for (std::size_t j = begin; j < end; ++j) {
    const Vec3 q = R_line.transpose() * ev.g[j];
    if (!(q.z() > 0.0)) continue;
    const double s = dir.dot(q.head<2>() / q.z());
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  out.length_px = hi >= lo ? (hi - lo) * focal_px : 0.0;
  out.status = LineFitStatus::Ok;
  out.rms_ok = out.length_ok = true;
  if (!out.line.normal.allFinite() || !std::isfinite(out.rms_px) || !std::isfinite(out.length_px)) {
    out.status = LineFitStatus::PoorFit;
    out.rms_ok = out.length_ok = false;
  }
  return out;
}

}  // namespace celc::detail
