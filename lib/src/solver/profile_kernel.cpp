// The line profile's per-direction algebra in lanes (profile_kernel.hpp).
// Every operation is written out in the order the former scalar form's
// Eigen expressions gave (products, trace and determinant included), and
// the file is compiled without floating-point contraction, so the profile's
// values, and celc_ml's answers, are the ones that form gave, bit for bit.
#include "profile_kernel.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "isa_clones.hpp"
#include "ml_screen.hpp"

namespace celc::detail {

namespace {

constexpr size_t kLanes = 8;
constexpr int kNewtonIterations = 10;

/// Q = S - X^T X of one cluster at v (its 6 entries q00 q01 q02 q11 q12 q22),
/// with X = L^-1 B^T and H = L L^T: S - B H^-1 B^T, the line's direction
/// eliminated (ml_screen.hpp).
struct SymQ {
  double q00, q01, q02, q11, q12, q22;
};
CELC_PASS_INLINE SymQ clusterQ(const double* s, double v0, double v1, double v2) {
  const double* S = s;
  const double* beta = s + 9;
  const double* Hq = s + 36;
  double h[6];
#pragma GCC unroll 6
  for (int p = 0; p < 6; ++p) {
    const double* m = Hq + 9 * p;
    const double w0 = m[0] * v0 + m[1] * v1 + m[2] * v2;
    const double w1 = m[3] * v0 + m[4] * v1 + m[5] * v2;
    const double w2 = m[6] * v0 + (m[7] * v1 + m[8] * v2);  // Eigen's order for the last row
    h[p] = v0 * w0 + v1 * w1 + v2 * w2;
  }
  double B[3][3];
#pragma GCC unroll 3
  for (int a = 0; a < 3; ++a)
#pragma GCC unroll 3
    for (int j = 0; j < 3; ++j) {
      const double* b = beta + 9 * a + 3 * j;
      B[a][j] = b[0] * v0 + b[1] * v1 + b[2] * v2;
    }
  // H is singular along the direction that moves the line along the
  // camera's path (exactly v when P = tau I), and B(v) vanishes there too:
  // a relative ridge of 1e-9 (H's diagonal += 1e-9 trace(H) + 1e-300) keeps
  // H positive definite and leaves the minimum over d unchanged but for
  // rounding. (i00, i11, i22: the reciprocals of L's diagonal.)
  const double ridge = 1e-9 * (h[0] + (h[3] + h[5])) + 1e-300;
  const double H00 = h[0] + ridge, H10 = h[1], H20 = h[2], H11 = h[3] + ridge, H21 = h[4], H22 = h[5] + ridge;
  const double i00 = 1.0 / std::sqrt(H00), l10 = H10 * i00, l20 = H20 * i00;
  const double i11 = 1.0 / std::sqrt(H11 - l10 * l10), l21 = (H21 - l20 * l10) * i11;
  const double i22 = 1.0 / std::sqrt(H22 - l20 * l20 - l21 * l21);
  double X[3][3];
#pragma GCC unroll 3
  for (int j = 0; j < 3; ++j) {
    X[0][j] = B[j][0] * i00;
    X[1][j] = (B[j][1] - l10 * X[0][j]) * i11;
    X[2][j] = (B[j][2] - l20 * X[0][j] - l21 * X[1][j]) * i22;
  }
  // (X^T X)_ij = sum_r X_ri X_rj, written out (a lambda holding X by
  // reference kept it in memory and the lanes' loop scalar).
  SymQ q;
  q.q00 = S[0] - (X[0][0] * X[0][0] + X[1][0] * X[1][0] + X[2][0] * X[2][0]);
  q.q01 = S[1] - (X[0][0] * X[0][1] + X[1][0] * X[1][1] + X[2][0] * X[2][1]);
  q.q02 = S[2] - (X[0][0] * X[0][2] + X[1][0] * X[1][2] + X[2][0] * X[2][2]);
  q.q11 = S[4] - (X[0][1] * X[0][1] + X[1][1] * X[1][1] + X[2][1] * X[2][1]);
  q.q12 = S[5] - (X[0][1] * X[0][2] + X[1][1] * X[1][2] + X[2][1] * X[2][2]);
  q.q22 = S[8] - (X[0][2] * X[0][2] + X[1][2] * X[1][2] + X[2][2] * X[2][2]);
  return q;
}

/// kLanes doubles, and the masks their comparisons give (all bits set where
/// true): GCC's vector extensions, lowered to the widest registers the ISA
/// clone has. Newton's iteration below has per-lane stopping rules, which
/// `#pragma omp simd` left scalar; written on whole vectors, it is not.
using Lanes = double __attribute__((vector_size(kLanes * sizeof(double))));
using Mask = std::int64_t __attribute__((vector_size(kLanes * sizeof(double))));

/// The coefficients of Q's characteristic polynomial
/// p(l) = l^3 - c2 l^2 + c1 l - c0: the trace, the sum of the principal 2x2
/// minors, the determinant (in the order Eigen forms them).
struct Cubic {
  double c0, c1, c2;
};
CELC_PASS_INLINE Cubic characteristic(const SymQ& q) {
  Cubic c;
  c.c2 = q.q00 + (q.q11 + q.q22);
  c.c1 = q.q00 * q.q11 - q.q01 * q.q01 + q.q00 * q.q22 - q.q02 * q.q02 + q.q11 * q.q22 - q.q12 * q.q12;
  c.c0 = q.q00 * (q.q11 * q.q22 - q.q12 * q.q12) - q.q01 * (q.q01 * q.q22 - q.q12 * q.q02) +
         q.q02 * (q.q01 * q.q12 - q.q11 * q.q02);
  return c;
}

/// The smallest root of each lane's cubic, clamped at 0 below, by
/// smallestEigenvalueClamped's iteration (ml_screen.hpp): the same steps
/// and stopping rules, every lane stepping until all have stopped or the
/// iterations run out. NaN where the scalar form hands over to the closed
/// form (a near-multiple root).
CELC_PASS_INLINE void newtonSmallest(const double* c0_in, const double* c1_in, const double* c2_in,
                                     double* out) {
  // (Arrays in and out: vectors of 8 doubles by value change the call ABI
  // between ISAs, which GCC warns about.)
  Lanes c0, c1, c2;
  std::memcpy(&c0, c0_in, sizeof c0), std::memcpy(&c1, c1_in, sizeof c1), std::memcpy(&c2, c2_in, sizeof c2);
  const Lanes zero = {};
  // Not all positive: a root at or below 0 (or NaN), the answer 0.
  Mask active = (c0 > zero) & (c1 > zero) & (c2 > zero);
  Mask failed = {};
  Lanes l = zero, last_step = zero + HUGE_VAL, result = zero;
  // In Newton's quadratic convergence a step s leaves an error of about
  // s^2 / (r2 - r1) <= s^2 / l: a step below 1e-8 l that is also below 1e-3
  // of the one before (not the halving of a double root) leaves less than
  // 1e-16 l. Where rounding stops the climb first, the step before must have
  // been below 1e-6 l. Otherwise (a near-multiple root, linear convergence,
  // good to eps^(1/2) or eps^(1/3) only) the lane fails over to the closed
  // form.
  for (int it = 0; it < kNewtonIterations; ++it) {
    const Lanes p = ((l - c2) * l + c1) * l - c0;
    const Lanes dp = (3.0 * l - 2.0 * c2) * l + c1;
    const Lanes quotient = -p / dp;
    const Lanes step = ((dp > zero) & (p < zero)) ? quotient : zero;
    const Mask moves = step > zero;
    const Mask stalled = active & ~moves;  // at the root to rounding, or stuck
    const Mask close = last_step <= 1e-6 * l;
    result = (stalled & close) ? l : result;
    failed |= stalled & ~close;
    const Mask advance = active & moves;
    const Lanes next = l + step;
    l = advance ? next : l;
    const Mask converged = advance & (step <= 1e-8 * next) & (step <= 1e-3 * last_step);
    result = converged ? l : result;
    last_step = advance ? step : last_step;
    active &= ~(stalled | converged);
    bool any = false;
    for (size_t k = 0; k < kLanes; ++k) any = any || active[k] != 0;
    if (!any) break;
  }
  const Lanes value = (failed | active) ? zero + std::numeric_limits<double>::quiet_NaN() : result;
  std::memcpy(out, &value, sizeof value);
}

/// The closed form where Newton's iteration hands over (Eigen, as the
/// scalar form).
double closedFormSmallest(const SymQ& q) {
  Eigen::Matrix3d Q;
  Q << q.q00, q.q01, q.q02, q.q01, q.q11, q.q12, q.q02, q.q12, q.q22;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(Q, Eigen::EigenvaluesOnly);
  return std::max(0.0, eig.eigenvalues()(0));
}

/// One cluster's values added to out[begin .. begin + count), count <= kLanes.
CELC_PASS_INLINE void clusterBlock(const double* s, const double* x, const double* y, const double* z,
                                   size_t begin, size_t count, double* out) {
  // The block's directions, lanes past count repeating its first (valid).
  double vx[kLanes], vy[kLanes], vz[kLanes];
  for (size_t l = 0; l < kLanes; ++l) {
    const size_t i = begin + (l < count ? l : 0);
    vx[l] = x[i], vy[l] = y[i], vz[l] = z[i];
  }
  // Per lane: Q's cubic, then the iteration on all lanes at once.
  double c0[kLanes], c1[kLanes], c2[kLanes], value[kLanes];
#pragma omp simd
  for (size_t l = 0; l < kLanes; ++l) {
    const Cubic c = characteristic(clusterQ(s, vx[l], vy[l], vz[l]));
    c0[l] = c.c0, c1[l] = c.c1, c2[l] = c.c2;
  }
  newtonSmallest(c0, c1, c2, value);
  for (size_t l = 0; l < count; ++l)
    out[begin + l] += std::isnan(value[l]) ? closedFormSmallest(clusterQ(s, vx[l], vy[l], vz[l])) : value[l];
}

CELC_ISA_CLONES void profileLanes(const double* sums, size_t clusters, const double* x, const double* y,
                                  const double* z, size_t n, double* out) {
  std::fill(out, out + n, 0.0);
  for (size_t c = 0; c < clusters; ++c)
    for (size_t b = 0; b < n; b += kLanes)
      clusterBlock(sums + c * kProfileSumsSize, x, y, z, b, std::min(kLanes, n - b), out);
}

}  // namespace

void profileValues(const double* sums, size_t clusters, const double* x, const double* y, const double* z,
                   size_t n, double* out) {
  profileLanes(sums, clusters, x, y, z, n, out);
}

// (One matrix in all 8 lanes: the profile's very iteration, for the tests
// and any single use; no hot path calls it.)
double smallestEigenvalueClamped(const Mat3& Q) {
  const SymQ q{Q(0, 0), Q(0, 1), Q(0, 2), Q(1, 1), Q(1, 2), Q(2, 2)};
  const Cubic c = characteristic(q);
  double c0[kLanes], c1[kLanes], c2[kLanes], value[kLanes];
  std::fill(c0, c0 + kLanes, c.c0), std::fill(c1, c1 + kLanes, c.c1), std::fill(c2, c2 + kLanes, c.c2);
  newtonSmallest(c0, c1, c2, value);
  const double l = value[0];
  return std::isnan(l) ? closedFormSmallest(q) : l;
}

}  // namespace celc::detail
