// The robust nullspace: IRLS with Huber weights, the closed-form 3x3
// generalised eigensolver of each step, and the grid of starts.
#include "robust_nullspace.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "irls_kernel.hpp"
#include "sampling.hpp"

namespace celc::detail {

namespace {
// Polishes an eigen-decomposition C ~ Y diag(d) Y^T of a symmetric 3x3 C by
// cyclic Jacobi sweeps on D = Y^T C Y until D is diagonal to rounding. Eigen's
// closed-form computeDirect loses digits on the eigenvector of an eigenvalue
// much smaller than the largest; from its nearly diagonal D one sweep, rarely
// two, restores full accuracy.
void jacobiPolish(const Mat3& C, Mat3& Y, Vec3& d) {
  Mat3 D = Y.transpose() * C * Y;
  const double tiny = 1e-18 * D.cwiseAbs().maxCoeff();
  for (int sweep = 0; sweep < 6; ++sweep) {
    bool rotated = false;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const double apq = D(p, q);
        if (!(std::abs(apq) > tiny)) continue;
        rotated = true;
        // Rotation in the (p, q) plane that zeroes D(p, q):
        // t = tan(angle), the smaller root of t^2 + 2 theta t - 1 = 0.
        const double theta = (D(q, q) - D(p, p)) / (2.0 * apq);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        // D <- J^T D J and Y <- Y J with J the rotation (c, s) in the
        // (p, q) plane: only rows and columns p and q change.
        for (int k = 0; k < 3; ++k) {  // columns: D J
          const double dp = D(k, p), dq = D(k, q);
          D(k, p) = c * dp - s * dq, D(k, q) = s * dp + c * dq;
          const double yp = Y(k, p), yq = Y(k, q);
          Y(k, p) = c * yp - s * yq, Y(k, q) = s * yp + c * yq;
        }
        for (int k = 0; k < 3; ++k) {  // rows: J^T (D J)
          const double dp = D(p, k), dq = D(q, k);
          D(p, k) = c * dp - s * dq, D(q, k) = s * dp + c * dq;
        }
        D(p, q) = D(q, p) = 0.0;
      }
    if (!rotated) break;
  }
  d = D.diagonal();
}
}  // namespace

bool generalizedEigen3(const Mat3& A, const Mat3& B, Vec3& values, Mat3& vectors) {
  // B = L L^T, L lower triangular with a positive diagonal.
  const double l00s = B(0, 0);
  if (!(l00s > 0.0)) return false;
  const double l00 = std::sqrt(l00s), l10 = B(1, 0) / l00, l20 = B(2, 0) / l00;
  const double l11s = B(1, 1) - l10 * l10;
  if (!(l11s > 0.0)) return false;
  const double l11 = std::sqrt(l11s), l21 = (B(2, 1) - l20 * l10) / l11;
  const double l22s = B(2, 2) - l20 * l20 - l21 * l21;
  if (!(l22s > 0.0)) return false;
  const double l22 = std::sqrt(l22s);
  // L^-1 by forward substitution; C = L^-1 A L^-T is symmetric with the same
  // eigenvalues, and its eigenvectors y give x = L^-T y (x^T B x = y^T y = 1).
  Mat3 Linv = Mat3::Zero();
  Linv(0, 0) = 1.0 / l00;
  Linv(1, 1) = 1.0 / l11;
  Linv(2, 2) = 1.0 / l22;
  Linv(1, 0) = -l10 * Linv(0, 0) / l11;
  Linv(2, 1) = -l21 * Linv(1, 1) / l22;
  Linv(2, 0) = -(l20 * Linv(0, 0) + l21 * Linv(1, 0)) / l22;
  Mat3 C = Linv * A * Linv.transpose();
  C = 0.5 * (C + C.transpose()).eval();
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(C);
  if (eig.info() != Eigen::Success || !C.allFinite()) return false;
  Mat3 Y = eig.eigenvectors();
  Vec3 d;
  jacobiPolish(C, Y, d);
  // Ascending order.
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return d(i) < d(j); });
  for (int i = 0; i < 3; ++i) {
    values(i) = d(order[i]);
    vectors.col(i) = Linv.transpose() * Y.col(order[i]);
  }
  return values.allFinite() && vectors.allFinite();
}

namespace {
// The symmetric matrix of the entries xx yy zz xy xz yz.
Mat3 unpack(const double* q) {
  Mat3 M;
  M << q[0], q[3], q[4], q[3], q[1], q[5], q[4], q[5], q[2];
  return M;
}

// The MAD scale 1.4826 * median |r| of r = a.v / |N v| over the scale sample
// of the rows (median of r^2: no square root per row). Rows with |N v| = 0
// count as r = r_degenerate. median_r2 carries the median r^2 from one call
// to the next (NaN at first): the next median is looked for within a factor
// 1.5 of it first (kthSmallest), the same value either way.
double sampledMad(const PackedRows& P, const Vec3& v, double r_degenerate, std::vector<double>& r2,
                  std::vector<double>& band, double& median_r2) {
  P.scaleSample().squaredResiduals(v, r_degenerate, r2);
  if (r2.empty()) return 0.0;
  median_r2 = kthSmallest(r2, r2.size() / 2, median_r2 / 1.5, median_r2 * 1.5, band);
  const double r2_degenerate = std::min(r_degenerate * r_degenerate, std::numeric_limits<double>::max());
  return 1.4826 * (median_r2 == r2_degenerate ? r_degenerate : std::sqrt(median_r2));
}

// IRLS from a starting direction. Each step solves the generalised
// eigenproblem (sum w_i a_i a_i^T) v = lambda (sum w_i N_i^T N_i) v with
// w_i = Huber(r_i / scale) / |N_i v_prev|^2 (then, with tukey_k, Tukey's
// biweight: an MM-style redescending stage from the Huber fixed point). A plain weighted eigenvector
// (denominator frozen) walks toward directions where a whole cluster's
// transferred lines collapse (|N v| -> 0 makes a.v -> 0 too); keeping the
// weighted normaliser on the right-hand side penalises that collapse, and at a
// fixed point lambda is the weighted squared geometric residual.
//
// An iteration is the scale from a strided sample of rows, then one fused
// pass over every row for the weights and the weighted sums (irls_kernel).
//
// Where the two smallest generalised eigenvalues are close (a weakly
// determined direction) the fixed-point step can overshoot and settle into a
// 2-cycle, whose end point then depends on the iteration count's parity. So
// the step is relaxed: v moves by a share of the fixed-point step, 1 at
// first and halved whenever a step reverses the previous one (negative dot
// product); the fixed points are unchanged. In the Tukey stage a step that
// shrinks along the previous one (ratio q = s_k.s_{k-1} / |s_{k-1}|^2 in
// (0, 1): linear convergence at rate q) lengthens the share by 1 / (1 - q),
// q taken at most 0.5 and the share at most 2, the extrapolation to the
// fixed point of a linear map.
NullspaceSolution irlsFrom(const PackedRows& P, Vec3 v, const LinearOptions& opt) {
  NullspaceSolution out;
  std::vector<double> sample, band;
  double median_r2 = NAN;
  Vec3 lambda;
  Mat3 X;
  Vec3 last_step = Vec3::Zero();
  Vec3 last_raw_step = Vec3::Zero();
  double relax = 1.0;  // share of the fixed-point step taken, halved at every reversal
  double scale = NAN;
  // Huber's IRLS to convergence, then (tukey_k > 0) Tukey's from its end point.
  const double chord_tolerance = 2.0 * std::sin(0.5 * opt.tolerance);
  const int huber_iterations = std::max(1, opt.max_iterations);
  const int iterations = huber_iterations * (opt.tukey_k > 0.0 ? 2 : 1);
  for (int it = 0; it < iterations; ++it) {
    const bool tukey = it >= huber_iterations;
    if (it == huber_iterations) {  // a new fixed-point map: its own relaxation
      last_step = Vec3::Zero();
      last_raw_step = Vec3::Zero();
      relax = 1.0;
    }
    // Tukey's stage keeps the scale of the Huber end point (an MM-estimator's
    // fixed scale): one fixed-point map, and no MAD per pass.
    if (!tukey || it == huber_iterations) scale = sampledMad(P, v, 0.0, sample, band, median_r2);
    const double thr = (tukey ? opt.tukey_k : opt.huber_k) * std::max(scale, 1e-15);
    const PackedSums s = weightedSums(P, v, tukey ? RobustLoss::tukey(thr) : RobustLoss::huber(thr));
    const Mat3 Ma = unpack(s.data()), Mn = unpack(s.data() + 6);
    if (!generalizedEigen3(Ma, Mn, lambda, X)) {
      if (tukey) break;  // no row within Tukey's threshold: keep the Huber end point
      return out;
    }
    Vec3 next = X.col(0).normalized();
    if (next.dot(v) < 0.0) next = -next;
    // Singular values of the normalised system: sqrt of the generalised
    // eigenvalues, the weighted RMS geometric residual along each direction.
    out.sigma_min = std::sqrt(std::max(0.0, lambda(0)));
    out.sigma_second = std::sqrt(std::max(0.0, lambda(1)));
    ++out.iterations;
    const Vec3 step = next - v;
    const double ratio = step.dot(last_raw_step) / std::max(last_raw_step.squaredNorm(), 1e-300);
    if (tukey && ratio > 0.0 && step.squaredNorm() < last_raw_step.squaredNorm()) {
      relax = std::min(relax / (1.0 - std::min(ratio, 0.5)), 2.0);
    } else if (step.dot(last_step) < 0.0) {
      relax *= 0.5;
    }
    last_raw_step = step;
    next = (v + relax * step).normalized();
    last_step = next - v;
    // The step's angle is below the tolerance when its chord is below
    // 2 sin(tolerance / 2) (both unit vectors; no acos per pass).
    const bool converged = last_step.norm() < chord_tolerance;
    v = next;
    if (converged) {
      if (tukey || opt.tukey_k <= 0.0) break;
      it = huber_iterations - 1;  // converged under Huber: on to Tukey's weights
    }
  }
  out.v = v;
  // Robust scale at the end point (rows with |N v| = 0 count as outliers).
  out.scale = sampledMad(P, v, 1e300, sample, band, median_r2);
  out.ok = v.allFinite() && v.norm() > 0.5;
  return out;
}

}  // namespace

// Once `keep` directions are scored, a direction with at most half its
// residuals within the keep-th smallest median so far has a larger median
// and cannot be among the best: one counting pass rejects it, without the
// selection of its median.
std::vector<Vec3> gridStarts(const PackedRows& P, int n, int keep_max, int rows) {
  const PackedRows sub = P.strided(P.size() / static_cast<size_t>(std::max(1, rows)));
  std::vector<std::pair<double, Vec3>> scored;
  std::vector<double> r2, medians;
  const size_t wanted = static_cast<size_t>(std::max(0, keep_max));
  double bound = std::numeric_limits<double>::infinity();  // the wanted-th smallest median so far
  for (const Vec3& d : hemisphereDirections(n)) {
    sub.squaredResiduals(d, 1e300, r2);
    const size_t half = r2.size() / 2;
    if (scored.size() >= wanted && bound < std::numeric_limits<double>::infinity()) {
      size_t within = 0;
      for (double x : r2) within += x <= bound ? 1 : 0;
      if (within <= half) continue;  // its median (the half-th smallest) exceeds the bound
    }
    auto mid = r2.begin() + static_cast<long>(half);
    std::nth_element(r2.begin(), mid, r2.end());
    scored.emplace_back(*mid, d);
    if (wanted > 0 && scored.size() >= wanted) {
      medians.clear();
      for (const auto& entry : scored) medians.push_back(entry.first);
      std::nth_element(medians.begin(), medians.begin() + static_cast<long>(wanted - 1), medians.end());
      bound = medians[wanted - 1];
    }
  }
  const size_t keep = std::min(scored.size(), wanted);
  std::partial_sort(scored.begin(), scored.begin() + static_cast<long>(keep), scored.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Vec3> out;
  for (size_t i = 0; i < keep; ++i) out.push_back(scored[i].second);
  return out;
}

const std::vector<Vec3>& hemisphereDirections(int n) {
  thread_local std::map<int, std::vector<Vec3>> lattices;  // nodes: references stay valid
  const auto found = lattices.find(n);
  if (found != lattices.end()) return found->second;
  std::vector<Vec3>& dirs = lattices[n];
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) / n;  // (0, 1)
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    dirs.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return dirs;
}

NullspaceSolution robustNullspace(const std::vector<ConstraintRow>& rows,
                                  const LinearOptions& opt) {
  return robustNullspace(PackedRows(rows), opt);
}

NullspaceSolution robustNullspace(const PackedRows& P, const LinearOptions& opt) {
  if (P.size() < 3) return {};
  std::vector<Vec3> starts;
  // Start 1: minimise sum (a_i.v)^2 / sum |N_i v|^2, the generalised eigenproblem
  // (sum a a^T) v = lambda (sum N^T N) v.
  const PackedSums& s = P.plainSums();
  const Mat3 Ma = unpack(s.data()), Mn = unpack(s.data() + 6);
  Vec3 lambda;
  Mat3 X;
  if (generalizedEigen3(Ma, Mn, lambda, X)) starts.push_back(X.col(0).normalized());
  // Further starts: the cost has a local minimum near each cluster's own line
  // direction (there that cluster's transferred lines become blends of l1 and
  // l3 and fit its events well), so one local start may not be enough.
  if (opt.grid_directions > 0 && opt.grid_starts > 0)
    for (const Vec3& d : gridStarts(P, opt.grid_directions, opt.grid_starts, opt.grid_rows))
      starts.push_back(d);
  // Keep the start whose IRLS ends with the lowest robust geometric cost.
  NullspaceSolution best;
  for (const Vec3& start : starts) {
    if (!start.allFinite()) continue;
    NullspaceSolution sol = irlsFrom(P, start, opt);
    if (sol.ok && (!best.ok || sol.scale < best.scale)) best = sol;
  }
  return best;
}

}  // namespace celc::detail
