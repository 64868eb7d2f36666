#pragma once
// Internal: celc_ml's screen of the velocity direction by the profile of the
// event-line constraint (no fitted lines needed).
//
// An event k with bearing b_k = R_k f_k (reference frame, unit) seen from the
// camera centre c_k = P_k v lies on the 3D line L (direction d, moment m) iff
// its ray meets L:
//   r_k = b_k.m + ((P_k v) x b_k).d = b_k.n_k = 0,   n_k = m + c_k x d,
// n_k being the normal of the line's interpretation plane at t_k (n at the
// reference time is m). For a given v, r is linear in (d, m). With |m| = 1
// (which excludes the line through the camera's own path, a trivial zero of
// r; r_k is then the event's angle to the plane up to |n_k| / |m|), the line
// of a cluster is eliminated in closed form:
//   E_c(v) = min_{|m| = 1, d} sum_k r_k^2 = lambda_min(S - B(v) H(v)^+ B(v)^T),
//   S = sum b b^T,  B(v) = sum b h_k(v)^T,  H(v) = sum h_k(v) h_k(v)^T,
//   h_k(v) = (P_k v) x b_k = K_k v,  K_k = -[b_k]_x P_k,
// where H's entries are quadratic forms in v and B's linear forms, summed
// once per cluster. The profile J(v) = sum_c E_c(v) is the algebraic cost
// with every line at its best for v; it is cheap (a 3x3 system per cluster
// and direction) and, unlike the joint refinement, has no line start to
// fall from.
#include <cstdint>
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"

namespace celc::detail {

/// The smallest eigenvalue of a symmetric 3x3 matrix, clamped at 0 below.
/// Its characteristic polynomial p(l) = l^3 - c2 l^2 + c1 l - c0 (c2 the
/// trace, c1 the sum of the principal 2x2 minors, c0 the determinant) has
/// only positive roots when c0, c1, c2 > 0 (Descartes), and otherwise a root
/// at or below 0. Below its smallest root r1, p rises and is concave, so
/// Newton's iteration from l = 0 climbs to r1 without overshoot: quadratically
/// where r1 is apart from the other roots (the profile's case: a line's
/// residual against two large spreads). Near a double or triple root it
/// converges linearly and only to eps^(1/2) or eps^(1/3): Eigen's closed form
/// answers there instead. (profile_kernel.cpp: the profile runs the same
/// iteration on 8 directions at a time.)
double smallestEigenvalueClamped(const Mat3& Q);

/// The profile J(v) of a window's clusters.
class LineProfile {
 public:
  /// Clusters `clusters` of obs, at most max_events events of each (a seeded
  /// subset, cluster i drawn with seed + i; 0 = all).
  LineProfile(const WindowObservations& obs, const MotionModel& motion,
              const std::vector<int>& clusters, int max_events, std::uint64_t seed);
  /// J(v) for a unit v [rad^2: squared angles up to |n_k| / |m|].
  double operator()(const Vec3& v) const;
  /// out[i] = J(dirs[i]), i < n: the same values, up to 8 directions in
  /// about the time of one (profile_kernel.hpp).
  void values(const Vec3* dirs, size_t n, double* out) const;
  /// Clusters summed.
  size_t size() const { return clusters_; }

 private:
  /// Each cluster's sums, packed as profile_kernel.hpp lays them out: S
  /// (3x3), the linear forms beta[a][j] with B(v)_aj = beta[a][j].v, and
  /// the quadratic forms of H(v)_ij = v^T Hq[ij] v (ij over the 6 pairs
  /// i <= j).
  std::vector<double> sums_;
  size_t clusters_ = 0;
};

/// The screen's result: local minima of J, lowest first.
struct ScreenMinimum {
  Vec3 v;
  double cost;
};

/// Local minima of J over the hemisphere: J on a lattice of `lattice`
/// directions, then a damped Newton descent on the tangent plane (steps
/// down to `tolerance_deg`) from the lattice's `keep` lowest separated
/// points; minima closer than `separation_deg` merge.
std::vector<ScreenMinimum> screenProfile(const LineProfile& profile, int lattice, int keep,
                                         double tolerance_deg, double separation_deg);

}  // namespace celc::detail
