// celc_ml's screen: the profile of the event-line constraint over directions.
#include "ml_screen.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "celc/solver/result.hpp"
#include "profile_kernel.hpp"
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

LineProfile::LineProfile(const WindowObservations& obs, const MotionModel& motion,
                         const std::vector<int>& clusters, int max_events, std::uint64_t seed) {
  for (size_t i = 0; i < clusters.size(); ++i) {
    const ClusterObservation& cl = obs.clusters[static_cast<size_t>(clusters[i])];
    struct {
      Mat3 S;
      Vec3 beta[3][3];
      Mat3 Hq[6];
    } s;
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
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) sums_.push_back(s.S(r, c));
    for (int a = 0; a < 3; ++a)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) sums_.push_back(s.beta[a][j](k));
    for (int p = 0; p < 6; ++p)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) sums_.push_back(s.Hq[p](r, c));
    ++clusters_;
  }
}

void LineProfile::values(const Vec3* dirs, size_t n, double* out) const {
  constexpr size_t kBatch = 128;  // directions per kernel call (on the stack)
  double x[kBatch], y[kBatch], z[kBatch];
  for (size_t b = 0; b < n; b += kBatch) {
    const size_t m = std::min(kBatch, n - b);
    for (size_t i = 0; i < m; ++i) x[i] = dirs[b + i].x(), y[i] = dirs[b + i].y(), z[i] = dirs[b + i].z();
    profileValues(sums_.data(), clusters_, x, y, z, m, out + b);
  }
}

double LineProfile::operator()(const Vec3& v) const {
  double out;
  values(&v, 1, &out);
  return out;
}

namespace {

/// Damped Newton descent of J on the tangent plane at s.v, from the 6-point
/// finite-difference quadratic model (gradient and Hessian at spacing h);
/// steps at most max_step [rad], halved until J falls, until a step is
/// below tol [rad]. Where the model is not convex the step follows the
/// negative gradient. (A pattern search of 8 tangent directions needed
/// several times as many evaluations of J; docs/accuracy.md.)
void descend(const LineProfile& profile, ScreenMinimum& s, double max_step, double tol) {
  const double h = std::max(tol, 1e-4);
  for (int it = 0; it < 20; ++it) {
    const Mat32 B = tangentBasis(s.v);
    auto at = [&](double a, double b) -> Vec3 { return (s.v + a * B.col(0) + b * B.col(1)).normalized(); };
    // The stencil's 5 values in one call.
    const Vec3 stencil[5] = {at(h, 0), at(-h, 0), at(0, h), at(0, -h), at(h, h)};
    double j5[5];
    profile.values(stencil, 5, j5);
    const double jp1 = j5[0], jm1 = j5[1], jp2 = j5[2], jm2 = j5[3], jpp = j5[4];
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
    // Halve until J falls; a step below tol ends the descent. The halvings
    // are evaluated up to 8 at a time and the first that falls is taken.
    bool moved = false;
    constexpr int kHalvings = 8;
    while (!moved && step.norm() >= tol) {
      Vec3 c[kHalvings];
      int n = 0;
      for (; n < kHalvings && step.norm() >= tol; ++n, step *= 0.5) c[n] = (s.v + B * step).normalized();
      double j[kHalvings];
      profile.values(c, static_cast<size_t>(n), j);
      for (int k = 0; k < n && !moved; ++k)
        if (j[k] < s.cost) {
          s = {c[k], j[k]};
          moved = true;
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
  std::vector<double> values(dirs.size());
  profile.values(dirs.data(), dirs.size(), values.data());
  std::vector<ScreenMinimum> grid;
  grid.reserve(dirs.size());
  for (size_t i = 0; i < dirs.size(); ++i) grid.push_back({dirs[i], values[i]});
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
