#include "irls_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

// Runtime dispatch: GCC builds one clone of each pass per listed target and
// picks the best the CPU supports when the program loads (an ifunc).
// (Not when the whole build already targets AVX-512: GCC 12 fails on the
// clones then, and there is nothing better to dispatch to.)
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__AVX512F__)
#define CELC_MULTIVERSION \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define CELC_INLINE inline __attribute__((always_inline))
#else
#define CELC_MULTIVERSION
#define CELC_INLINE inline
#endif

namespace celc::detail {

namespace {
constexpr size_t L = PackedRows::kLanes;
using LaneSums = double[12][L];

// L doubles as one value (GCC/Clang vector extension): an instruction set
// with narrower registers splits it (AVX2: 2 x 4, SSE2: 4 x 2 lanes), so
// every clone computes the same lanes in the same order.
using Lanes = double __attribute__((vector_size(L * sizeof(double))));

using LaneMask = long long __attribute__((vector_size(L * sizeof(double))));
static_assert(sizeof(long long) == sizeof(double), "lanes and masks have the same width");

CELC_INLINE void loadLanes(const double* p, Lanes& x) { __builtin_memcpy(&x, p, sizeof x); }
// out = m ? a : b lane by lane (m from a comparison: all ones or all zeros).
CELC_INLINE void select(const LaneMask& m, const Lanes& a, const Lanes& b, Lanes& out) {
  out = reinterpret_cast<Lanes>((m & reinterpret_cast<LaneMask>(a)) | (~m & reinterpret_cast<LaneMask>(b)));
}

// One pass over n rows (a multiple of L) stored as columns c (stride s; a,
// then R rows of N): per row the weight w (Huber over |N v|^2, or 1 when
// kPlain) and the sums of w a a^T and w N^T N, lane by lane.
template <int R, bool kPlain>
CELC_INLINE void sumsPass(const double* c, size_t n, size_t s, const double* v, double thr,
                          LaneSums& out) {
  Lanes acc[12];
  for (Lanes& x : acc) x = Lanes{} ;
  for (size_t b = 0; b < n; b += L) {
    Lanes a0, a1, a2, N[R][3];
    loadLanes(c + b, a0), loadLanes(c + s + b, a1), loadLanes(c + 2 * s + b, a2);
    for (int r = 0; r < R; ++r)
      for (int k = 0; k < 3; ++k) loadLanes(c + static_cast<size_t>(3 + 3 * r + k) * s + b, N[r][k]);
    Lanes w = Lanes{} + 1.0;
    if (!kPlain) {
      const Lanes d = a0 * v[0] + a1 * v[1] + a2 * v[2];
      Lanes g2 = Lanes{};
      for (int r = 0; r < R; ++r) {
        const Lanes u = N[r][0] * v[0] + N[r][1] * v[1] + N[r][2] * v[2];
        g2 += u * u;
      }
      // One square root and one division per row: w = T / sqrt(X) with
      // (T, X) = (1, g2^2) for an inlier (sqrt(g2^2) == g2 exactly in IEEE
      // arithmetic) and (thr, d^2 g2) for an outlier (|r| >= thr).
      const LaneMask inlier = d * d < thr * thr * g2;
      Lanes T, X;
      select(inlier, Lanes{} + 1.0, Lanes{} + thr, T);
      select(inlier, g2 * g2, d * d * g2, X);
      double x[L];
      __builtin_memcpy(x, &X, sizeof x);
      for (size_t l = 0; l < L; ++l) x[l] = std::sqrt(x[l]);
      Lanes root;
      __builtin_memcpy(&root, x, sizeof x);
      select(g2 > Lanes{}, T / root, Lanes{}, w);
    }
    const Lanes wa0 = w * a0, wa1 = w * a1, wa2 = w * a2;
    acc[0] += wa0 * a0, acc[1] += wa1 * a1, acc[2] += wa2 * a2;
    acc[3] += wa0 * a1, acc[4] += wa0 * a2, acc[5] += wa1 * a2;
    for (int r = 0; r < R; ++r) {
      const Lanes wn0 = w * N[r][0], wn1 = w * N[r][1], wn2 = w * N[r][2];
      acc[6] += wn0 * N[r][0], acc[7] += wn1 * N[r][1], acc[8] += wn2 * N[r][2];
      acc[9] += wn0 * N[r][1], acc[10] += wn0 * N[r][2], acc[11] += wn1 * N[r][2];
    }
  }
  for (int k = 0; k < 12; ++k)
    for (size_t l = 0; l < L; ++l) out[k][l] = acc[k][l];
}

CELC_MULTIVERSION void huberPass2(const double* c, size_t n, size_t s, const double* v, double thr,
                                  LaneSums& out) {
  sumsPass<2, false>(c, n, s, v, thr, out);
}
CELC_MULTIVERSION void huberPass3(const double* c, size_t n, size_t s, const double* v, double thr,
                                  LaneSums& out) {
  sumsPass<3, false>(c, n, s, v, thr, out);
}
CELC_MULTIVERSION void plainPass2(const double* c, size_t n, size_t s, LaneSums& out) {
  sumsPass<2, true>(c, n, s, nullptr, 0.0, out);
}
CELC_MULTIVERSION void plainPass3(const double* c, size_t n, size_t s, LaneSums& out) {
  sumsPass<3, true>(c, n, s, nullptr, 0.0, out);
}

// r2_k = (a_k.v)^2 / |N_k v|^2 (r2_degenerate where |N_k v| = 0) over m rows
// stored as columns c (stride s) in PackedRows' layout.
template <int R>
CELC_INLINE void squaredResiduals(const double* c, size_t m, size_t s, const double* v,
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
CELC_MULTIVERSION void squaredResiduals2(const double* c, size_t m, size_t s, const double* v,
                                         double r2_degenerate, double* r2) {
  squaredResiduals<2>(c, m, s, v, r2_degenerate, r2);
}
CELC_MULTIVERSION void squaredResiduals3(const double* c, size_t m, size_t s, const double* v,
                                         double r2_degenerate, double* r2) {
  squaredResiduals<3>(c, m, s, v, r2_degenerate, r2);
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

void PackedRows::sealWithoutSample() {
  padded_ = (n_ + kLanes - 1) / kLanes * kLanes;
  double* c = data_.get();
  const size_t columns = 3 + 3 * static_cast<size_t>(normal_rows_);
  for (size_t j = 0; j < columns; ++j) std::fill(c + j * stride_ + n_, c + j * stride_ + padded_, 0.0);
  LaneSums plain;
  if (normal_rows_ == 2)
    plainPass2(c, padded_, stride_, plain);
  else
    plainPass3(c, padded_, stride_, plain);
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

PackedSums huberWeightedSums(const PackedRows& rows, const Vec3& v, double thr) {
  const double vv[3] = {v.x(), v.y(), v.z()};
  LaneSums acc;
  if (rows.normalRows() == 2)
    huberPass2(rows.data(), rows.paddedSize(), rows.stride(), vv, thr, acc);
  else
    huberPass3(rows.data(), rows.paddedSize(), rows.stride(), vv, thr, acc);
  return laneTotals(acc);
}

}  // namespace celc::detail
