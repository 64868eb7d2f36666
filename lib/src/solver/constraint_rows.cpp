#include "constraint_rows.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_set>

namespace celc::detail {

ClusterFrame makeClusterFrame(const ClusterObservation& c, const MotionModel& motion) {
  ClusterFrame f;
  f.m1 = motion.rotation(c.l1.t) * c.l1.normal;
  f.m3 = motion.rotation(c.l3.t) * c.l3.normal;
  f.Ps = motion.positionMatrix(c.l1.t);
  f.Pe = motion.positionMatrix(c.l3.t);
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
// Robust geometric cost of v: 1.4826 * median |a_i.v / |N_i v||.
double robustScale(const std::vector<ConstraintRow>& rows, const Vec3& v, std::vector<double>& r) {
  r.resize(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const double g = (rows[i].N * v).norm();
    r[i] = g > 0.0 ? rows[i].a.dot(v) / g : 1e300;
  }
  return 1.4826 * medianAbs(r);
}

// The 6 distinct entries of a a^T and of N^T N (symmetric) of each row,
// packed contiguously once, so an IRLS iteration is ~30 flops per row.
struct Packed {
  double a[3];
  double aa[6];  // xx yy zz xy xz yz
  double nn[6];
};
std::vector<Packed> pack(const std::vector<ConstraintRow>& rows) {
  std::vector<Packed> P(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const Vec3& a = rows[i].a;
    const Mat3 NN = rows[i].N.transpose() * rows[i].N;
    P[i] = {{a.x(), a.y(), a.z()},
            {a.x() * a.x(), a.y() * a.y(), a.z() * a.z(), a.x() * a.y(), a.x() * a.z(), a.y() * a.z()},
            {NN(0, 0), NN(1, 1), NN(2, 2), NN(0, 1), NN(0, 2), NN(1, 2)}};
  }
  return P;
}
double quad(const double* q, const Vec3& v) {
  return q[0] * v.x() * v.x() + q[1] * v.y() * v.y() + q[2] * v.z() * v.z() +
         2.0 * (q[3] * v.x() * v.y() + q[4] * v.x() * v.z() + q[5] * v.y() * v.z());
}
Mat3 unpack(const double* q) {
  Mat3 M;
  M << q[0], q[3], q[4], q[3], q[1], q[5], q[4], q[5], q[2];
  return M;
}
// Robust scale of the geometric residuals at v from a strided sample of at
// most 256 rows (relative standard error ~5%).
double sampledScale(const std::vector<Packed>& P, const Vec3& v) {
  const size_t stride = std::max<size_t>(1, P.size() / 256);
  std::vector<double> r;
  for (size_t i = 0; i < P.size(); i += stride) {
    const double g = std::sqrt(std::max(0.0, quad(P[i].nn, v)));
    r.push_back(g > 0.0 ? (P[i].a[0] * v.x() + P[i].a[1] * v.y() + P[i].a[2] * v.z()) / g : 1e300);
  }
  return 1.4826 * medianAbs(r);
}

// IRLS from a starting direction. Each step solves the generalised
// eigenproblem (sum w_i a_i a_i^T) v = lambda (sum w_i N_i^T N_i) v with
// w_i = Huber(r_i / scale) / |N_i v_prev|^2. A plain weighted eigenvector
// (denominator frozen) walks toward directions where a whole cluster's
// transferred lines collapse (|N v| -> 0 makes a.v -> 0 too); keeping the
// weighted normaliser on the right-hand side penalises that collapse, and at a
// fixed point lambda is the weighted squared geometric residual.
NullspaceSolution irlsFrom(const std::vector<Packed>& P, Vec3 v, int max_iterations,
                           double huber_k, double tolerance) {
  NullspaceSolution out;
  const size_t n = P.size();
  // The MAD scale from a strided subset of at most 256 rows (its relative
  // standard error is ~5%, well inside what the Huber threshold needs).
  const size_t stride = std::max<size_t>(1, n / 256);
  std::vector<double> r(n), g(n), sample;
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> eig;
  for (int it = 0; it < std::max(1, max_iterations); ++it) {
    sample.clear();
    for (size_t i = 0; i < n; ++i) {
      g[i] = std::sqrt(std::max(0.0, quad(P[i].nn, v)));
      r[i] = g[i] > 0.0 ? (P[i].a[0] * v.x() + P[i].a[1] * v.y() + P[i].a[2] * v.z()) / g[i] : 0.0;
      if (i % stride == 0) sample.push_back(r[i]);
    }
    const double scale = 1.4826 * medianAbs(sample);
    const double thr = huber_k * std::max(scale, 1e-15);
    double sa[6] = {0, 0, 0, 0, 0, 0}, sn[6] = {0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
      if (!(g[i] > 1e-300)) continue;
      const double huber = std::abs(r[i]) <= thr ? 1.0 : thr / std::abs(r[i]);
      const double w = huber / (g[i] * g[i]);
      for (int k = 0; k < 6; ++k) {
        sa[k] += w * P[i].aa[k];
        sn[k] += w * P[i].nn[k];
      }
    }
    const Mat3 Ma = unpack(sa), Mn = unpack(sn);
    eig.compute(Ma, Mn);
    if (eig.info() != Eigen::Success) return out;
    Vec3 next = eig.eigenvectors().col(0).normalized();
    if (next.dot(v) < 0.0) next = -next;
    // Singular values of the normalised system: sqrt of the generalised
    // eigenvalues, the weighted RMS geometric residual along each direction.
    out.sigma_min = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
    out.sigma_second = std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
    out.iterations = it + 1;
    const double delta = std::acos(std::min(1.0, next.dot(v)));
    v = next;
    if (delta < tolerance) break;
  }
  out.v = v;
  out.scale = sampledScale(P, v);
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
  if (rows.size() < 3) return {};
  std::vector<Vec3> starts;
  // Start 1: minimise sum (a_i.v)^2 / sum |N_i v|^2, the generalised eigenproblem
  // (sum a a^T) v = lambda (sum N^T N) v.
  const std::vector<Packed> P = pack(rows);
  double sa[6] = {0, 0, 0, 0, 0, 0}, sn[6] = {0, 0, 0, 0, 0, 0};
  for (const auto& p : P)
    for (int k = 0; k < 6; ++k) {
      sa[k] += p.aa[k];
      sn[k] += p.nn[k];
    }
  const Mat3 Ma = unpack(sa), Mn = unpack(sn);
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> gen(Ma, Mn);
  if (gen.info() == Eigen::Success) starts.push_back(gen.eigenvectors().col(0).normalized());
  // Further starts: the best directions of a coarse grid over the hemisphere,
  // scored by the robust geometric cost on a strided subset of rows. The cost
  // has a local minimum near each cluster's own line direction (there the
  // transferred lines of that cluster become blends of l1 and l3 and fit its
  // events well), so a single local start is not enough.
  if (opt.grid_directions > 0 && opt.grid_starts > 0) {
    std::vector<ConstraintRow> sub;
    const size_t stride = std::max<size_t>(1, rows.size() / std::max(1, opt.grid_rows));
    for (size_t i = 0; i < rows.size(); i += stride) sub.push_back(rows[i]);
    std::vector<std::pair<double, Vec3>> scored;
    std::vector<double> r;
    for (const Vec3& d : hemisphereDirections(opt.grid_directions))
      scored.emplace_back(robustScale(sub, d, r), d);
    const size_t keep = std::min(scored.size(), static_cast<size_t>(opt.grid_starts));
    std::partial_sort(scored.begin(), scored.begin() + static_cast<long>(keep), scored.end(),
                      [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t i = 0; i < keep; ++i) starts.push_back(scored[i].second);
  }
  // Keep the start whose IRLS ends with the lowest robust geometric cost.
  NullspaceSolution best;
  for (const Vec3& s : starts) {
    if (!s.allFinite()) continue;
    NullspaceSolution sol = irlsFrom(P, s, opt.max_iterations, opt.huber_k, opt.tolerance);
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
