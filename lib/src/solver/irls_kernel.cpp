// The IRLS passes over packed rows: plain loops over the columns that the
// compiler vectorises across the lanes of a block (`#pragma omp simd`).
#include "irls_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "isa_clones.hpp"

namespace celc::detail {

namespace {
constexpr size_t L = PackedRows::kLanes;
using LaneSums = double[12][L];

// One pass over n rows (a multiple of L) stored as columns c (stride s; a,
// then R rows of N). Row b + l of each block b adds to lane l's sums: the
// weight w (Huber's or Tukey's of r = a.v / |N v| at the threshold thr, over
// |N v|^2; or 1 without a loss), then w a a^T and w N^T N.
template <int R, RobustLoss::Type kWeights>
CELC_PASS_INLINE void sumsPass(const double* c, size_t n, size_t s, const double* v, double thr,
                     LaneSums& out) {
  LaneSums acc = {};  // local: nothing the loop stores aliases the columns it reads
  constexpr bool kPlain = kWeights == RobustLoss::Type::None;
  const double v0 = kPlain ? 0.0 : v[0], v1 = kPlain ? 0.0 : v[1], v2 = kPlain ? 0.0 : v[2];
  const double thr2 = thr * thr;
  for (size_t b = 0; b < n; b += L) {
#pragma omp simd
    for (size_t l = 0; l < L; ++l) {
      const size_t i = b + l;
      const double a0 = c[i], a1 = c[s + i], a2 = c[2 * s + i];
      double N[R][3];
      for (int r = 0; r < R; ++r)
        for (int k = 0; k < 3; ++k) N[r][k] = c[static_cast<size_t>(3 + 3 * r + k) * s + i];
      double w = 1.0;
      if (!kPlain) {
        // d = a.v and g2 = |N v|^2: the geometric residual is r = d / sqrt(g2).
        const double d = a0 * v0 + a1 * v1 + a2 * v2;
        double g2 = 0.0;
        for (int r = 0; r < R; ++r) {
          const double u = N[r][0] * v0 + N[r][1] * v1 + N[r][2] * v2;
          g2 += u * u;
        }
        const double d2 = d * d;
        if (kWeights == RobustLoss::Type::Tukey) {
          // (1 - r^2 / thr^2)^2 / g2 for |r| < thr, else 0.
          const double q = 1.0 - d2 / (thr2 * g2);
          w = g2 > 0.0 && q > 0.0 ? q * q / g2 : 0.0;
        } else {
          // One square root and one division per row: w = T / sqrt(X) with
          // (T, X) = (1, g2^2) for an inlier (sqrt(g2^2) == g2 exactly in IEEE
          // arithmetic) and (thr, d^2 g2) for an outlier (|r| >= thr).
          // Both sides computed, then selected: the loop has no branch.
          const bool inlier = d2 < thr2 * g2;
          const double T = inlier ? 1.0 : thr;
          const double X = inlier ? g2 * g2 : d2 * g2;
          const double weight = T / std::sqrt(X);
          w = g2 > 0.0 ? weight : 0.0;
        }
      }
      const double wa0 = w * a0, wa1 = w * a1, wa2 = w * a2;
      acc[0][l] += wa0 * a0, acc[1][l] += wa1 * a1, acc[2][l] += wa2 * a2;
      acc[3][l] += wa0 * a1, acc[4][l] += wa0 * a2, acc[5][l] += wa1 * a2;
      for (int r = 0; r < R; ++r) {
        const double wn0 = w * N[r][0], wn1 = w * N[r][1], wn2 = w * N[r][2];
        acc[6][l] += wn0 * N[r][0], acc[7][l] += wn1 * N[r][1], acc[8][l] += wn2 * N[r][2];
        acc[9][l] += wn0 * N[r][1], acc[10][l] += wn0 * N[r][2], acc[11][l] += wn1 * N[r][2];
      }
    }
  }
  std::copy(&acc[0][0], &acc[0][0] + 12 * L, &out[0][0]);
}

// Every pass (R rows of N kept; plain, Huber or Tukey weights).
CELC_ISA_CLONES void sums(int R, RobustLoss::Type weights, const double* c, size_t n, size_t s, const double* v,
                          double thr, LaneSums& out) {
  if (R == 2 && weights == RobustLoss::Type::None) sumsPass<2, RobustLoss::Type::None>(c, n, s, v, thr, out);
  if (R == 2 && weights == RobustLoss::Type::Huber) sumsPass<2, RobustLoss::Type::Huber>(c, n, s, v, thr, out);
  if (R == 2 && weights == RobustLoss::Type::Tukey) sumsPass<2, RobustLoss::Type::Tukey>(c, n, s, v, thr, out);
  if (R == 3 && weights == RobustLoss::Type::None) sumsPass<3, RobustLoss::Type::None>(c, n, s, v, thr, out);
  if (R == 3 && weights == RobustLoss::Type::Huber) sumsPass<3, RobustLoss::Type::Huber>(c, n, s, v, thr, out);
  if (R == 3 && weights == RobustLoss::Type::Tukey) sumsPass<3, RobustLoss::Type::Tukey>(c, n, s, v, thr, out);
}

// r2_k = (a_k.v)^2 / |N_k v|^2 (r2_degenerate where |N_k v| = 0) over m rows
// stored as columns c (stride s) in PackedRows' layout.
template <int R>
CELC_PASS_INLINE void squaredResiduals(const double* c, size_t m, size_t s, const double* v,
                                  double r2_degenerate, double* r2) {
#pragma omp simd
  for (size_t k = 0; k < m; ++k) {
    const double d = c[k] * v[0] + c[s + k] * v[1] + c[2 * s + k] * v[2];
    double g2 = 0.0;
    for (int r = 0; r < R; ++r) {
      const double* n = c + (3 + 3 * r) * s + k;
      const double u = n[0] * v[0] + n[s] * v[1] + n[2 * s] * v[2];
      g2 += u * u;
    }
    const double r2_row = d * d / g2;
    r2[k] = g2 > 0.0 ? r2_row : r2_degenerate;
  }
}
CELC_ISA_CLONES void squaredResiduals2(const double* c, size_t m, size_t s, const double* v,
                                         double r2_degenerate, double* r2) {
  squaredResiduals<2>(c, m, s, v, r2_degenerate, r2);
}
CELC_ISA_CLONES void squaredResiduals3(const double* c, size_t m, size_t s, const double* v,
                                         double r2_degenerate, double* r2) {
  squaredResiduals<3>(c, m, s, v, r2_degenerate, r2);
}

// Row i of the columns from an event's terms (EventLineTerms: g1, g3, u,
// s) and bearing f: a = (g1.f) u - (g3.f) s and N's rows g1_r u - g3_r s,
// at c (the row's entry in column 0; stride s).
CELC_PASS_INLINE void writeRow(const double (&g1)[3], const double (&g3)[3], const double (&u)[3],
                               const double (&sv)[3], double fx, double fy, double fz, double* c, size_t s) {
  const double al = g1[0] * fx + g1[1] * fy + g1[2] * fz;
  const double be = g3[0] * fx + g3[1] * fy + g3[2] * fz;
  for (int j = 0; j < 3; ++j) {
    c[static_cast<size_t>(j) * s] = al * u[j] - be * sv[j];
    c[static_cast<size_t>(3 + j) * s] = g1[0] * u[j] - g3[0] * sv[j];
    c[static_cast<size_t>(6 + j) * s] = g1[1] * u[j] - g3[1] * sv[j];
  }
}

// The CELC rows of m events under a constant twist (constants q: t_ref, w2,
// then m1 m3 u0 s0 wm1 wm3 wwm1 wwm3, 3 each), into columns c (stride s) from
// row 0: ClusterRowTerms::at and ::row, one event per lane.
CELC_ISA_CLONES void twistRows(const double* q, const double* t, const double* fx, const double* fy,
                               const double* fz, size_t m, double* c, size_t s) {
  const double t_ref = q[0], w2 = q[1];
  const double* m1 = q + 2; const double* m3 = q + 5; const double* u0 = q + 8; const double* s0 = q + 11;
  const double* wm1 = q + 14; const double* wm3 = q + 17; const double* wwm1 = q + 20; const double* wwm3 = q + 23;
#pragma omp simd
  for (size_t i = 0; i < m; ++i) {
    const double tau = t[i] - t_ref, tau2 = tau * tau, x = w2 * tau2;
    double A, B, C;
    so3::seriesCoefficients(x, A, B, C);
    const double ra = A * tau, rb = B * tau2, pc = C * tau2 * tau;
    double g1[3], g3[3], u[3], sv[3];
    for (int j = 0; j < 3; ++j) {
      g1[j] = m1[j] - ra * wm1[j] + rb * wwm1[j];
      g3[j] = m3[j] - ra * wm3[j] + rb * wwm3[j];
      u[j] = u0[j] - (tau * m3[j] - rb * wm3[j] + pc * wwm3[j]);
      sv[j] = s0[j] - (tau * m1[j] - rb * wm1[j] + pc * wwm1[j]);
    }
    writeRow(g1, g3, u, sv, fx[i], fy[i], fz[i], c + i, s);
  }
}

// The CELC rows of m events in one piece of a gyro-integrated model
// (constants q: t0, w0, h, m1', m3', U, S, m1, m3, 3 each after t0), into
// columns c (stride s) from row 0: ClusterRowTerms::row, one event per lane.
template <bool kBody>
CELC_PASS_INLINE void gyroRows(const double* q, const double* t, const double* fx, const double* fy,
                     const double* fz, size_t m, double* c, size_t s) {
  const double t0 = q[0];
  const double* w0 = q + 1; const double* h = q + 4;
  const double* m1r = q + 7; const double* m3r = q + 10; const double* U = q + 13;
  const double* S = q + 16; const double* m1 = q + 19; const double* m3 = q + 22;
#pragma omp simd
  for (size_t i = 0; i < m; ++i) {
    const double dt = t[i] - t0;
    const double px = (w0[0] + h[0] * dt) * dt, py = (w0[1] + h[1] * dt) * dt, pz = (w0[2] + h[2] * dt) * dt;
    double A, B, C;
    so3::seriesCoefficients(px * px + py * py + pz * pz, A, B, C);
    // c1 = phi x m1', c2 = phi x c1; d1, d2 the same for m3'.
    const double c1[3] = {py * m1r[2] - pz * m1r[1], pz * m1r[0] - px * m1r[2], px * m1r[1] - py * m1r[0]};
    const double c2[3] = {py * c1[2] - pz * c1[1], pz * c1[0] - px * c1[2], px * c1[1] - py * c1[0]};
    const double d1[3] = {py * m3r[2] - pz * m3r[1], pz * m3r[0] - px * m3r[2], px * m3r[1] - py * m3r[0]};
    const double d2[3] = {py * d1[2] - pz * d1[1], pz * d1[0] - px * d1[2], px * d1[1] - py * d1[0]};
    double g1[3], g3[3], u[3], sv[3];
    for (int j = 0; j < 3; ++j) {
      g1[j] = m1r[j] - A * c1[j] + B * c2[j];
      g3[j] = m3r[j] - A * d1[j] + B * d2[j];
      const double p1 = kBody ? m1r[j] - B * c1[j] + C * c2[j] : m1[j];
      const double p3 = kBody ? m3r[j] - B * d1[j] + C * d2[j] : m3[j];
      u[j] = U[j] - dt * p3;
      sv[j] = S[j] - dt * p1;
    }
    writeRow(g1, g3, u, sv, fx[i], fy[i], fz[i], c + i, s);
  }
}
CELC_ISA_CLONES void gyroRowsBody(const double* q, const double* t, const double* fx, const double* fy,
                                  const double* fz, size_t m, double* c, size_t s) {
  gyroRows<true>(q, t, fx, fy, fz, m, c, s);
}
CELC_ISA_CLONES void gyroRowsReference(const double* q, const double* t, const double* fx,
                                       const double* fy, const double* fz, size_t m, double* c, size_t s) {
  gyroRows<false>(q, t, fx, fy, fz, m, c, s);
}

// 0 when the m rows of the first `columns` columns (stride s) are all
// finite, else NaN (x * 0 is NaN exactly for an infinite or NaN x).
CELC_ISA_CLONES double zeroUnlessNotFinite(const double* c, size_t columns, size_t m, size_t s) {
  double sum = 0.0;
  for (size_t j = 0; j < columns; ++j)
#pragma omp simd reduction(+ : sum)
    for (size_t i = 0; i < m; ++i) sum += c[j * s + i] * 0.0;
  return sum;
}

// The lanes' partial sums added in a fixed order.
PackedSums laneTotals(const LaneSums& acc) {
  PackedSums out{};
  for (size_t k = 0; k < 12; ++k)
    for (size_t l = 0; l < L; ++l) out[k] += acc[k][l];
  return out;
}

// Column stride in doubles: at least n and = 16 (mod 512), so that columns
// start 128 bytes apart modulo 4 KiB (loads from columns a multiple of 4 KiB
// apart would alias in the CPU's 4 KiB address check).
size_t columnStride(size_t n) { return n <= 16 ? 16 : (n - 16 + 511) / 512 * 512 + 16; }
}  // namespace

PackedRows::PackedRows(size_t capacity, int normal_rows)
    : capacity_(capacity),
      stride_(columnStride((capacity + kLanes - 1) / kLanes * kLanes)),
      normal_rows_(normal_rows == 2 ? 2 : 3),
      data_(new double[(3 + 3 * static_cast<size_t>(normal_rows_)) * stride_]) {}

namespace {
int normalRowsOf(const std::vector<ConstraintRow>& rows) {
  for (const ConstraintRow& row : rows)
    if (row.N(2, 0) != 0.0 || row.N(2, 1) != 0.0 || row.N(2, 2) != 0.0) return 3;
  return 2;
}
}  // namespace

PackedRows::PackedRows(const std::vector<ConstraintRow>& rows)
    : PackedRows(rows.size(), normalRowsOf(rows)) {
  for (const ConstraintRow& row : rows) append(row.a, row.N);
  seal();
}

bool PackedRows::append(const Vec3& a, const Mat3& N) {
  if (n_ >= capacity_) return false;
  double* c = data_.get() + n_;
  c[0] = a.x(), c[stride_] = a.y(), c[2 * stride_] = a.z();
  for (int r = 0; r < normal_rows_; ++r)
    for (int k = 0; k < 3; ++k) c[static_cast<size_t>(3 + 3 * r + k) * stride_] = N(r, k);
  ++n_;
  return true;
}

bool PackedRows::append(const Vec3& a, const Vec3& n0, const Vec3& n1) {
  if (n_ >= capacity_) return false;
  double* c = data_.get() + n_;
  const size_t s = stride_;
  c[0] = a.x(), c[s] = a.y(), c[2 * s] = a.z();
  c[3 * s] = n0.x(), c[4 * s] = n0.y(), c[5 * s] = n0.z();
  c[6 * s] = n1.x(), c[7 * s] = n1.y(), c[8 * s] = n1.z();
  if (normal_rows_ == 3) c[9 * s] = c[10 * s] = c[11 * s] = 0.0;
  ++n_;
  return true;
}

bool PackedRows::appendTwistRows(const TwistRowConstants& k, const double* t, const double* fx,
                                 const double* fy, const double* fz, size_t m) {
  if (normal_rows_ != 2 || m > capacity_ - n_) return false;
  double q[26] = {k.t_ref, k.w2};
  const Vec3* vectors[8] = {&k.m1, &k.m3, &k.u0, &k.s0, &k.wm1, &k.wm3, &k.wwm1, &k.wwm3};
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 3; ++i) q[2 + 3 * j + i] = (*vectors[j])(i);
  double* c = data_.get() + n_;
  twistRows(q, t, fx, fy, fz, m, c, stride_);
  if (!std::isfinite(zeroUnlessNotFinite(c, 9, m, stride_))) return false;
  n_ += m;
  return true;
}

bool PackedRows::appendGyroRows(const GyroRowConstants& k, const double* t, const double* fx,
                                const double* fy, const double* fz, size_t m) {
  if (normal_rows_ != 2 || m > capacity_ - n_) return false;
  double q[25] = {k.t0};
  const Vec3* vectors[8] = {&k.w0, &k.h, &k.m1r, &k.m3r, &k.U, &k.S, &k.m1, &k.m3};
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 3; ++i) q[1 + 3 * j + i] = (*vectors[j])(i);
  for (size_t i = 0; i < m; ++i) {
    const double dt = t[i] - k.t0;
    if (!(((k.w0 + k.h * dt) * dt).squaredNorm() < kTwistSeriesLimit)) return false;
  }
  double* c = data_.get() + n_;
  (k.body ? gyroRowsBody : gyroRowsReference)(q, t, fx, fy, fz, m, c, stride_);
  if (!std::isfinite(zeroUnlessNotFinite(c, 9, m, stride_))) return false;
  n_ += m;
  return true;
}

void PackedRows::sealWithoutSample() {
  padded_ = (n_ + kLanes - 1) / kLanes * kLanes;
  double* c = data_.get();
  const size_t columns = 3 + 3 * static_cast<size_t>(normal_rows_);
  for (size_t j = 0; j < columns; ++j) std::fill(c + j * stride_ + n_, c + j * stride_ + padded_, 0.0);
  LaneSums plain;
  sums(normal_rows_, RobustLoss::Type::None, c, padded_, stride_, nullptr, 0.0, plain);
  plain_sums_ = laneTotals(plain);
}

void PackedRows::seal() {
  sealWithoutSample();
  const size_t step = std::max<size_t>(1, n_ / kScaleSample);
  sample_.reset();
  if (step > 1) sample_ = std::make_shared<const PackedRows>(strided(step));
}

PackedRows PackedRows::strided(size_t step) const {
  step = std::max<size_t>(1, step);
  PackedRows out(n_ == 0 ? 0 : (n_ - 1) / step + 1, normal_rows_);
  const size_t columns = 3 + 3 * static_cast<size_t>(normal_rows_);
  for (size_t j = 0; j < columns; ++j) {
    const double* src = data_.get() + j * stride_;
    double* dst = out.data_.get() + j * out.stride_;
    for (size_t k = 0; k < out.capacity_; ++k) dst[k] = src[k * step];
  }
  out.n_ = out.capacity_;
  out.sealWithoutSample();
  return out;
}

void PackedRows::squaredResiduals(const Vec3& v, double r_degenerate, std::vector<double>& r2) const {
  const double r2_degenerate = std::min(r_degenerate * r_degenerate, std::numeric_limits<double>::max());
  r2.resize(n_);
  const double vv[3] = {v.x(), v.y(), v.z()};
  if (normal_rows_ == 2)
    squaredResiduals2(data_.get(), n_, stride_, vv, r2_degenerate, r2.data());
  else
    squaredResiduals3(data_.get(), n_, stride_, vv, r2_degenerate, r2.data());
}

PackedSums weightedSums(const PackedRows& rows, const Vec3& v, const RobustLoss& loss) {
  const double vv[3] = {v.x(), v.y(), v.z()};
  LaneSums acc;
  sums(rows.normalRows(), loss.type, rows.data(), rows.paddedSize(), rows.stride(), vv, loss.scale, acc);
  return laneTotals(acc);
}

}  // namespace celc::detail
