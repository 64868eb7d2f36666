// celc_ml's screen: the profile of the event-line constraint over directions.
#include "ml_screen.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "celc/solver/result.hpp"
#include "robust_nullspace.hpp"
#include "sampling.hpp"
#include "sphere_tangent.hpp"

namespace celc::detail {

namespace {

constexpr int kPairs[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};

Mat3 skew(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

}  // namespace

double smallestEigenvalueClamped(const Mat3& Q) {
  const double c2 = Q.trace();
  const double c1 = Q(0, 0) * Q(1, 1) - Q(0, 1) * Q(0, 1) + Q(0, 0) * Q(2, 2) - Q(0, 2) * Q(0, 2) +
                    Q(1, 1) * Q(2, 2) - Q(1, 2) * Q(1, 2);
  const double c0 = Q.determinant();
  if (!(c0 > 0.0 && c1 > 0.0 && c2 > 0.0)) return 0.0;  // a root at or below 0 (or NaN)
  // In Newton's quadratic convergence a step s leaves an error of about
  // s^2 / (r2 - r1) <= s^2 / l: a step below 1e-8 l that is also below
  // 1e-3 of the one before (not the halving of a double root) leaves less
  // than 1e-16 l. Where rounding stops the climb first, the step before must
  // have been below 1e-6 l. A near-multiple root (linear convergence, good to
  // eps^(1/2) or eps^(1/3) only) is left to the closed form.
  double l = 0.0, last_step = HUGE_VAL;
  for (int it = 0; it < 10; ++it) {
    const double p = ((l - c2) * l + c1) * l - c0;
    const double dp = (3.0 * l - 2.0 * c2) * l + c1;
    const double step = dp > 0.0 && p < 0.0 ? -p / dp : 0.0;
    if (!(step > 0.0)) {  // at r1 to rounding
      if (last_step <= 1e-6 * l) return l;
      break;
    }
    l += step;
    if (step <= 1e-8 * l && step <= 1e-3 * last_step) return l;
    last_step = step;
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(Q, Eigen::EigenvaluesOnly);
  return std::max(0.0, eig.eigenvalues()(0));
}

LineProfile::LineProfile(const WindowObservations& obs, const MotionModel& motion,
                         const std::vector<int>& clusters, int max_events, std::uint64_t seed) {
  for (size_t i = 0; i < clusters.size(); ++i) {
    const ClusterObservation& cl = obs.clusters[static_cast<size_t>(clusters[i])];
    Sums s;
    s.S.setZero();
    for (auto& row : s.beta)
      for (Vec3& b : row) b.setZero();
    for (Mat3& h : s.Hq) h.setZero();
    int n = 0;
    for (size_t k : sampleIndices(cl.size(), static_cast<size_t>(std::max(0, max_events)), seed + i)) {
      const double t = cl.times[k];
      const Vec3& f = cl.bearings[k];
      if (!std::isfinite(t) || !f.allFinite() || !(f.norm() > 0.0)) continue;
      const Vec3 b = motion.rotate(t, f.normalized());
      const Mat3 K = -skew(b) * motion.positionMatrix(t);  // h = K v
      if (!b.allFinite() || !K.allFinite()) continue;
      s.S += b * b.transpose();
      for (int a = 0; a < 3; ++a)
        for (int j = 0; j < 3; ++j) s.beta[a][j] += b(a) * K.row(j).transpose();
      for (int p = 0; p < 6; ++p)
        s.Hq[p] += K.row(kPairs[p][0]).transpose() * K.row(kPairs[p][1]);
      ++n;
    }
    if (n < 5) continue;  // fewer events than a line and a plane need
    for (Mat3& h : s.Hq) h = 0.5 * (h + h.transpose()).eval();
    sums_.push_back(s);
  }
}

void LineProfile::forms(const Sums& s, const Vec3& v, Mat3& H, Mat3& B) {
  for (int p = 0; p < 6; ++p) {
    const double q = v.dot(s.Hq[p] * v);
    H(kPairs[p][0], kPairs[p][1]) = q;
    H(kPairs[p][1], kPairs[p][0]) = q;
  }
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < 3; ++j) B(a, j) = s.beta[a][j].dot(v);
  // H is singular along the direction that moves the line along the
  // camera's path (exactly v when P = tau I), and B(v) vanishes there too:
  // a relative ridge of 1e-9 leaves the minimum over d unchanged but for
  // rounding.
  H.diagonal().array() += 1e-9 * H.trace() + 1e-300;
}

double LineProfile::operator()(const Vec3& v) const {
  double total = 0.0;
  for (const Sums& s : sums_) {
    Mat3 H, B;
    forms(s, v, H, B);
    // S - B H^-1 B^T = S - X^T X with H = L L^T and X = L^-1 B^T (H is
    // positive definite: the ridge in forms()).
    // (i00, i11, i22: the reciprocals of L's diagonal, one division each.)
    const double i00 = 1.0 / std::sqrt(H(0, 0)), l10 = H(1, 0) * i00, l20 = H(2, 0) * i00;
    const double i11 = 1.0 / std::sqrt(H(1, 1) - l10 * l10), l21 = (H(2, 1) - l20 * l10) * i11;
    const double i22 = 1.0 / std::sqrt(H(2, 2) - l20 * l20 - l21 * l21);
    Mat3 X;  // row r of X = L^-1 B^T, by forward substitution
    for (int j = 0; j < 3; ++j) {
      X(0, j) = B(j, 0) * i00;
      X(1, j) = (B(j, 1) - l10 * X(0, j)) * i11;
      X(2, j) = (B(j, 2) - l20 * X(0, j) - l21 * X(1, j)) * i22;
    }
    const Mat3 Q = s.S - X.transpose() * X;
    total += smallestEigenvalueClamped(0.5 * (Q + Q.transpose()));
  }
  return total;
}

namespace {

/// Damped Newton descent of J on the tangent plane at s.v, from the 6-point
/// finite-difference quadratic model (gradient and Hessian at spacing h);
/// steps at most max_step [rad], halved until J falls, until a step is
/// below tol [rad]. Where the model is not convex the step follows the
/// negative gradient. (A pattern search of 8 tangent directions needed
/// several times as many evaluations of J; docs/peers.md.)
void descend(const LineProfile& profile, ScreenMinimum& s, double max_step, double tol) {
  const double h = std::max(tol, 1e-4);
  for (int it = 0; it < 20; ++it) {
    const Mat32 B = tangentBasis(s.v);
    auto at = [&](double a, double b) { return profile((s.v + a * B.col(0) + b * B.col(1)).normalized()); };
    const double jp1 = at(h, 0), jm1 = at(-h, 0), jp2 = at(0, h), jm2 = at(0, -h), jpp = at(h, h);
    const Eigen::Vector2d g((jp1 - jm1) / (2 * h), (jp2 - jm2) / (2 * h));
    Eigen::Matrix2d H;
    H(0, 0) = (jp1 - 2 * s.cost + jm1) / (h * h);
    H(1, 1) = (jp2 - 2 * s.cost + jm2) / (h * h);
    H(0, 1) = H(1, 0) = (jpp - jp1 - jp2 + s.cost) / (h * h);
    Eigen::Vector2d step;
    const bool convex = H(0, 0) > 0 && H.determinant() > 0;
    if (convex) step = -H.ldlt().solve(g);
    else step = -g.normalized() * max_step;
    if (!step.allFinite()) return;
    if (step.norm() > max_step) step *= max_step / step.norm();
    // Halve until J falls; a step below tol ends the descent.
    bool moved = false;
    for (; step.norm() >= tol; step *= 0.5) {
      const Vec3 c = (s.v + B * step).normalized();
      const double j = profile(c);
      if (j < s.cost) {
        s = {c, j};
        moved = true;
        break;
      }
    }
    if (!moved) return;
  }
}

}  // namespace

std::vector<ScreenMinimum> screenProfile(const LineProfile& profile, int lattice, int keep,
                                         double tolerance_deg, double separation_deg) {
  std::vector<ScreenMinimum> out;
  if (profile.size() == 0 || lattice < 1 || keep < 1) return out;
  const std::vector<Vec3>& dirs = hemisphereDirections(lattice);
  std::vector<ScreenMinimum> grid;
  grid.reserve(dirs.size());
  for (const Vec3& d : dirs) grid.push_back({d, profile(d)});
  std::sort(grid.begin(), grid.end(),
            [](const ScreenMinimum& a, const ScreenMinimum& b) { return a.cost < b.cost; });
  // Lattice spacing on the hemisphere (2 pi sr): the longest descent step,
  // and the suppression radius among lattice starts.
  const double spacing = std::sqrt(2.0 * M_PI / static_cast<double>(dirs.size()));
  std::vector<ScreenMinimum> starts;
  for (const ScreenMinimum& g : grid) {
    bool near = false;
    for (const ScreenMinimum& s : starts) near = near || angleBetweenSignAgnostic(g.v, s.v) < 2.0 * spacing;
    if (!near) starts.push_back(g);
    if (static_cast<int>(starts.size()) >= keep) break;
  }
  const double tol = tolerance_deg * M_PI / 180.0;
  for (ScreenMinimum s : starts) {
    descend(profile, s, spacing, tol);
    bool merged = false;
    for (ScreenMinimum& o : out)
      if (angleBetweenSignAgnostic(o.v, s.v) * 180.0 / M_PI < separation_deg) {
        if (s.cost < o.cost) o = s;
        merged = true;
      }
    if (!merged) out.push_back(s);
  }
  std::sort(out.begin(), out.end(),
            [](const ScreenMinimum& a, const ScreenMinimum& b) { return a.cost < b.cost; });
  return out;
}

}  // namespace celc::detail
