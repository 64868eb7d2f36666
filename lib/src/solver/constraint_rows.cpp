#include "constraint_rows.hpp"

#include "irls_kernel.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <unordered_set>

namespace celc::detail {

ClusterFrame makeClusterFrame(const ClusterObservation& c, const MotionModel& motion) {
  ClusterFrame f;
  Mat3 R1, R3;
  motion.pose(c.l1.t, R1, f.Ps);
  motion.pose(c.l3.t, R3, f.Pe);
  f.m1 = R1 * c.l1.normal;
  f.m3 = R3 * c.l3.normal;
  return f;
}

namespace {
Mat3 transferFromP(const ClusterFrame& frame, const Mat3& Pk) {
  const Vec3 u = (frame.Pe - Pk).transpose() * frame.m3;
  const Vec3 s = (frame.Ps - Pk).transpose() * frame.m1;
  return frame.m1 * u.transpose() - frame.m3 * s.transpose();
}
}  // namespace

Mat3 transferMatrix(const ClusterFrame& frame, const MotionModel& motion, double t) {
  return transferFromP(frame, motion.positionMatrix(t));
}

Mat3 transferMatrix(const ClusterFrame& frame, const Mat3& P) { return transferFromP(frame, P); }

ConstraintRow celcRow(const ClusterFrame& frame, const MotionModel& motion, double t,
                      const Vec3& f) {
  Mat3 Rk, Pk;
  motion.pose(t, Rk, Pk);
  const Mat3 B_ref = transferFromP(frame, Pk);
  ConstraintRow row;
  row.a = B_ref.transpose() * (Rk * f);
  row.N.topRows<2>() = Rk.transpose().topRows<2>() * B_ref;
  row.N.row(2).setZero();
  return row;
}

double medianAbs(std::vector<double>& x) {
  if (x.empty()) return 0.0;
  for (double& v : x) v = std::abs(v);
  auto mid = x.begin() + static_cast<long>(x.size() / 2);
  std::nth_element(x.begin(), mid, x.end());
  return *mid;
}

namespace {
// Polishes an eigen-decomposition C ~ Y diag(d) Y^T of a symmetric 3x3 C by
// cyclic Jacobi sweeps on D = Y^T C Y until D is diagonal to rounding. Eigen's
// closed-form computeDirect is fast but loses digits on a small eigenvalue's
// eigenvector (errors ~1e-5 rad when it is 1e-8 of the largest); from its
// nearly diagonal D one sweep, rarely two, restores full accuracy.
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
        Mat3 J = Mat3::Identity();
        J(p, p) = c, J(q, q) = c, J(p, q) = s, J(q, p) = -s;
        D = (J.transpose() * D * J).eval();
        D(p, q) = D(q, p) = 0.0;
        Y = (Y * J).eval();
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
Mat3 unpack(const double* q) {
  Mat3 M;
  M << q[0], q[3], q[4], q[3], q[1], q[5], q[4], q[5], q[2];
  return M;
}
// The MAD scale 1.4826 * median |r| of r = a.v / |N v| over the scale sample
// of the rows (median of r^2: no square root per row). Rows with |N v| = 0
// count as r = r_degenerate.
double sampledMad(const PackedRows& P, const Vec3& v, double r_degenerate, std::vector<double>& r2) {
  P.scaleSample().squaredResiduals(v, r_degenerate, r2);
  if (r2.empty()) return 0.0;
  auto mid = r2.begin() + static_cast<long>(r2.size() / 2);
  std::nth_element(r2.begin(), mid, r2.end());
  const double r2_degenerate = std::min(r_degenerate * r_degenerate, std::numeric_limits<double>::max());
  return 1.4826 * (*mid == r2_degenerate ? r_degenerate : std::sqrt(*mid));
}

// The generalised eigenproblem in closed form or by Eigen's iterative solver.
bool generalizedEigen(const Mat3& A, const Mat3& B, bool closed_form, Vec3& values, Mat3& vectors) {
  if (closed_form) return generalizedEigen3(A, B, values, vectors);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> eig(A, B);
  if (eig.info() != Eigen::Success) return false;
  values = eig.eigenvalues();
  vectors = eig.eigenvectors();
  return true;
}

// IRLS from a starting direction. Each step solves the generalised
// eigenproblem (sum w_i a_i a_i^T) v = lambda (sum w_i N_i^T N_i) v with
// w_i = Huber(r_i / scale) / |N_i v_prev|^2. A plain weighted eigenvector
// (denominator frozen) walks toward directions where a whole cluster's
// transferred lines collapse (|N v| -> 0 makes a.v -> 0 too); keeping the
// weighted normaliser on the right-hand side penalises that collapse, and at a
// fixed point lambda is the weighted squared geometric residual.
//
// An iteration is the scale from a strided sample of rows, then one fused
// pass over every row for the weights and the weighted sums (irls_kernel).
NullspaceSolution irlsFrom(const PackedRows& P, Vec3 v, const NullspaceOptions& opt) {
  NullspaceSolution out;
  std::vector<double> sample;
  Vec3 lambda;
  Mat3 X;
  for (int it = 0; it < std::max(1, opt.max_iterations); ++it) {
    const double scale = sampledMad(P, v, 0.0, sample);
    const double thr = opt.huber_k * std::max(scale, 1e-15);
    const PackedSums s = huberWeightedSums(P, v, thr);
    const Mat3 Ma = unpack(s.data()), Mn = unpack(s.data() + 6);
    if (!generalizedEigen(Ma, Mn, opt.closed_form_eigen, lambda, X)) return out;
    Vec3 next = X.col(0).normalized();
    if (next.dot(v) < 0.0) next = -next;
    // Singular values of the normalised system: sqrt of the generalised
    // eigenvalues, the weighted RMS geometric residual along each direction.
    out.sigma_min = std::sqrt(std::max(0.0, lambda(0)));
    out.sigma_second = std::sqrt(std::max(0.0, lambda(1)));
    out.iterations = it + 1;
    const double delta = std::acos(std::min(1.0, next.dot(v)));
    v = next;
    if (delta < opt.tolerance) break;
  }
  out.v = v;
  // Robust scale at the end point (rows with |N v| = 0 count as outliers).
  out.scale = sampledMad(P, v, 1e300, sample);
  out.ok = v.allFinite() && v.norm() > 0.5;
  return out;
}
}  // namespace

std::vector<Vec3> hemisphereDirections(int n) {
  // Fibonacci lattice on the upper hemisphere (z >= 0): v and -v are one solution.
  std::vector<Vec3> dirs;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) / n;  // (0, 1)
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    dirs.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return dirs;
}

NullspaceSolution robustNullspace(const std::vector<ConstraintRow>& rows,
                                  const NullspaceOptions& opt) {
  return robustNullspace(PackedRows(rows), opt);
}

NullspaceSolution robustNullspace(const PackedRows& P, const NullspaceOptions& opt) {
  if (P.size() < 3) return {};
  std::vector<Vec3> starts;
  // Start 1: minimise sum (a_i.v)^2 / sum |N_i v|^2, the generalised eigenproblem
  // (sum a a^T) v = lambda (sum N^T N) v.
  const PackedSums& s = P.plainSums();
  const Mat3 Ma = unpack(s.data()), Mn = unpack(s.data() + 6);
  Vec3 lambda;
  Mat3 X;
  if (generalizedEigen(Ma, Mn, opt.closed_form_eigen, lambda, X)) starts.push_back(X.col(0).normalized());
  // Further starts: the best directions of a coarse grid over the hemisphere,
  // scored by the robust geometric cost (the MAD scale) on a strided subset
  // of rows. The cost has a local minimum near each cluster's own line
  // direction (there the transferred lines of that cluster become blends of
  // l1 and l3 and fit its events well), so a single local start is not enough.
  if (opt.grid_directions > 0 && opt.grid_starts > 0) {
    const PackedRows sub = P.strided(P.size() / static_cast<size_t>(std::max(1, opt.grid_rows)));
    std::vector<std::pair<double, Vec3>> scored;
    std::vector<double> r2;
    for (const Vec3& d : hemisphereDirections(opt.grid_directions)) {
      sub.squaredResiduals(d, 1e300, r2);
      auto mid = r2.begin() + static_cast<long>(r2.size() / 2);
      std::nth_element(r2.begin(), mid, r2.end());
      scored.emplace_back(*mid, d);  // the median r^2 ranks as the MAD does
    }
    const size_t keep = std::min(scored.size(), static_cast<size_t>(opt.grid_starts));
    std::partial_sort(scored.begin(), scored.begin() + static_cast<long>(keep), scored.end(),
                      [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t i = 0; i < keep; ++i) starts.push_back(scored[i].second);
  }
  // Keep the start whose IRLS ends with the lowest robust geometric cost.
  NullspaceSolution best;
  for (const Vec3& s : starts) {
    if (!s.allFinite()) continue;
    NullspaceSolution sol = irlsFrom(P, s, opt);
    if (sol.ok && (!best.ok || sol.scale < best.scale)) best = sol;
  }
  return best;
}

std::vector<int> usableClusters(const WindowObservations& obs, int min_events) {
  std::vector<int> idx;
  for (size_t c = 0; c < obs.clusters.size(); ++c) {
    const auto& cl = obs.clusters[c];
    if (static_cast<int>(cl.size()) < min_events || cl.bearings.size() != cl.times.size()) continue;
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
    f.push_back((motion.rotation(c.times[k]) * c.bearings[k]).normalized());
    tau.push_back((c.times[k] - tm) / half);
  }
  if (f.size() < 8) return out;
  // Static line: plane normal n minimising sum (n . f)^2.
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

// Seeded random subset of k indices out of n (sorted), or all when k >= n or k == 0.
std::vector<size_t> sampleIndices(size_t n, size_t k, std::uint64_t seed) {
  std::vector<size_t> idx;
  if (k == 0 || k >= n) {
    idx.resize(n);
    for (size_t i = 0; i < n; ++i) idx[i] = i;
    return idx;
  }
  // Floyd's algorithm: k draws, no O(n) buffer.
  std::mt19937_64 rng(seed);
  std::unordered_set<size_t> chosen;
  chosen.reserve(2 * k);
  for (size_t j = n - k; j < n; ++j) {
    const size_t t = std::uniform_int_distribution<size_t>(0, j)(rng);
    if (!chosen.insert(t).second) chosen.insert(j);
  }
  idx.assign(chosen.begin(), chosen.end());
  std::sort(idx.begin(), idx.end());
  return idx;
}

// Rows per cluster out of a budget (0 = every event). Balanced: water-filling,
// so that every cluster gets the same share unless it has fewer events (a long
// edge must not outvote the others); else proportional to the cluster sizes.
std::vector<size_t> rowQuota(const std::vector<size_t>& sizes, size_t budget, bool balanced) {
  size_t total = 0;
  for (size_t s : sizes) total += s;
  if (budget == 0 || total <= budget) return sizes;
  std::vector<size_t> q(sizes.size());
  if (!balanced) {
    for (size_t i = 0; i < sizes.size(); ++i) q[i] = sizes[i] * budget / total;
    return q;
  }
  std::vector<size_t> order(sizes.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return sizes[a] < sizes[b]; });
  size_t remaining = budget;
  for (size_t j = 0; j < order.size(); ++j) {
    const size_t share = remaining / (order.size() - j);
    q[order[j]] = std::min(sizes[order[j]], share);
    remaining -= q[order[j]];
  }
  return q;
}

}  // namespace celc::detail
