#include "irls_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

// Runtime dispatch (GCC on x86-64 Linux): a pass built for several targets,
// the best the CPU supports picked when the program loads (an ifunc); either
// one body compiled per target (CELC_MULTIVERSION) or, where the best vector
// width differs, one hand-picked body per target. Not when the whole build
// already targets AVX-512: nothing better to dispatch to (and GCC 12 fails
// on the clones then).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__AVX512F__)
#define CELC_DISPATCH 1
#define CELC_MULTIVERSION \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define CELC_DISPATCH 0
#define CELC_MULTIVERSION
#endif
#if defined(__GNUC__)
#define CELC_INLINE inline __attribute__((always_inline))
#else
#define CELC_INLINE inline
#endif

namespace celc::detail {

namespace {
constexpr size_t L = PackedRows::kLanes;
using LaneSums = double[12][L];

// W doubles as one value (GCC/Clang vector extension), W = 2, 4 or 8: one
// SSE2, AVX2 or AVX-512 register. A block of L = 8 lanes is L / W of them,
// each lane with its own sums, so every width computes the same lanes with
// the same operations in the same order: the sums agree to rounding (AVX2
// and AVX-512 fuse multiply-adds, SSE2 cannot).
// (The vector size is spelled out per width: GCC ignores it on an alias
// template with a dependent size.)
template <int W>
struct WideTypes;
template <>
struct WideTypes<2> {
  typedef double V __attribute__((vector_size(16)));
  typedef long long M __attribute__((vector_size(16)));
};
template <>
struct WideTypes<4> {
  typedef double V __attribute__((vector_size(32)));
  typedef long long M __attribute__((vector_size(32)));
};
template <>
struct WideTypes<8> {
  typedef double V __attribute__((vector_size(64)));
  typedef long long M __attribute__((vector_size(64)));
};
template <int W>
using Wide = typename WideTypes<W>::V;
template <int W>
using WideMask = typename WideTypes<W>::M;
static_assert(sizeof(long long) == sizeof(double), "lanes and masks have the same width");

template <typename V>
CELC_INLINE void load(const double* p, V& x) { __builtin_memcpy(&x, p, sizeof x); }
template <typename V>
CELC_INLINE void broadcast(double a, V& x) { x = V{} + a; }
// out = m ? a : b lane by lane (m from a comparison: all ones or all zeros).
template <typename V, typename M>
CELC_INLINE void select(const M& m, const V& a, const V& b, V& out) {
  out = reinterpret_cast<V>((m & reinterpret_cast<M>(a)) | (~m & reinterpret_cast<M>(b)));
}

// The constants of a pass, one per lane.
template <typename V>
struct PassConstants {
  V v0, v1, v2, one, zero, thr, thr2;
};

// Rows i .. i+W-1 of the columns c (stride s; a, then R rows of N) into their
// lanes' sums A: the weight w (Huber over |N v|^2, or 1 when kPlain), then
// w a a^T and w N^T N.
template <int W, int R, bool kPlain>
CELC_INLINE void accumulate(const double* c, size_t s, size_t i, const PassConstants<Wide<W>>& k,
                            Wide<W> (&A)[12]) {
  using V = Wide<W>;
  V a0, a1, a2, N[R][3];
  load(c + i, a0), load(c + s + i, a1), load(c + 2 * s + i, a2);
#pragma GCC unroll 9
  for (int e = 0; e < 3 * R; ++e) load(c + static_cast<size_t>(3 + e) * s + i, N[e / 3][e % 3]);
  V w = k.one;
  if (!kPlain) {
    const V d = a0 * k.v0 + a1 * k.v1 + a2 * k.v2;
    V g2 = k.zero;
#pragma GCC unroll 3
    for (int r = 0; r < R; ++r) {
      const V u = N[r][0] * k.v0 + N[r][1] * k.v1 + N[r][2] * k.v2;
      g2 += u * u;
    }
    // One square root and one division per row: w = T / sqrt(X) with
    // (T, X) = (1, g2^2) for an inlier (sqrt(g2^2) == g2 exactly in IEEE
    // arithmetic) and (thr, d^2 g2) for an outlier (|r| >= thr).
    const WideMask<W> inlier = d * d < k.thr2 * g2;
    V T, X, root;
    select(inlier, k.one, k.thr, T);
    select(inlier, g2 * g2, d * d * g2, X);
    double x[W];
    __builtin_memcpy(x, &X, sizeof x);
#pragma GCC unroll 8
    for (int l = 0; l < W; ++l) x[l] = std::sqrt(x[l]);
    __builtin_memcpy(&root, x, sizeof x);
    select(g2 > k.zero, T / root, k.zero, w);
  }
  const V wa0 = w * a0, wa1 = w * a1, wa2 = w * a2;
  A[0] += wa0 * a0, A[1] += wa1 * a1, A[2] += wa2 * a2;
  A[3] += wa0 * a1, A[4] += wa0 * a2, A[5] += wa1 * a2;
#pragma GCC unroll 3
  for (int r = 0; r < R; ++r) {
    const V wn0 = w * N[r][0], wn1 = w * N[r][1], wn2 = w * N[r][2];
    A[6] += wn0 * N[r][0], A[7] += wn1 * N[r][1], A[8] += wn2 * N[r][2];
    A[9] += wn0 * N[r][1], A[10] += wn0 * N[r][2], A[11] += wn1 * N[r][2];
  }
}

// One pass over n rows (a multiple of L), L / W vectors per block.
template <int W, int R, bool kPlain>
CELC_INLINE void sumsPass(const double* c, size_t n, size_t s, const double* v, double thr,
                          LaneSums& out) {
  constexpr int P = static_cast<int>(L) / W;
  static_assert(P * W == static_cast<int>(L), "a block is whole vectors");
  PassConstants<Wide<W>> k;
  broadcast(kPlain ? 0.0 : v[0], k.v0), broadcast(kPlain ? 0.0 : v[1], k.v1);
  broadcast(kPlain ? 0.0 : v[2], k.v2), broadcast(1.0, k.one), broadcast(0.0, k.zero);
  broadcast(thr, k.thr), broadcast(thr * thr, k.thr2);
  Wide<W> acc[P][12];
  for (auto& part : acc)
    for (auto& x : part) x = k.zero;
  for (size_t b = 0; b < n; b += L) {
#pragma GCC unroll 4
    for (int p = 0; p < P; ++p) accumulate<W, R, kPlain>(c, s, b + static_cast<size_t>(p * W), k, acc[p]);
  }
  for (int j = 0; j < 12; ++j)
    for (int p = 0; p < P; ++p) __builtin_memcpy(&out[j][p * W], &acc[p][j], sizeof acc[p][j]);
}

// Every pass at width W (R rows of N kept; plain or Huber weights).
template <int W>
CELC_INLINE void sumsAnyPass(int R, bool plain, const double* c, size_t n, size_t s, const double* v,
                             double thr, LaneSums& out) {
  if (R == 2 && plain) sumsPass<W, 2, true>(c, n, s, v, thr, out);
  if (R == 2 && !plain) sumsPass<W, 2, false>(c, n, s, v, thr, out);
  if (R == 3 && plain) sumsPass<W, 3, true>(c, n, s, v, thr, out);
  if (R == 3 && !plain) sumsPass<W, 3, false>(c, n, s, v, thr, out);
}

#if CELC_DISPATCH
__attribute__((target("arch=x86-64-v4"))) void sums(int R, bool plain, const double* c, size_t n, size_t s,
                                                     const double* v, double thr, LaneSums& out) {
  sumsAnyPass<8>(R, plain, c, n, s, v, thr, out);
}
__attribute__((target("arch=x86-64-v3"))) void sums(int R, bool plain, const double* c, size_t n, size_t s,
                                                     const double* v, double thr, LaneSums& out) {
  sumsAnyPass<4>(R, plain, c, n, s, v, thr, out);
}
__attribute__((target("default"))) void sums(int R, bool plain, const double* c, size_t n, size_t s,
                                             const double* v, double thr, LaneSums& out) {
  sumsAnyPass<2>(R, plain, c, n, s, v, thr, out);
}
#else
void sums(int R, bool plain, const double* c, size_t n, size_t s, const double* v, double thr,
          LaneSums& out) {
#if defined(__AVX512F__)
  sumsAnyPass<8>(R, plain, c, n, s, v, thr, out);
#elif defined(__AVX__)
  sumsAnyPass<4>(R, plain, c, n, s, v, thr, out);
#else
  sumsAnyPass<2>(R, plain, c, n, s, v, thr, out);
#endif
}
#endif

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
  sums(normal_rows_, true, c, padded_, stride_, nullptr, 0.0, plain);
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
  sums(rows.normalRows(), false, rows.data(), rows.paddedSize(), rows.stride(), vv, thr, acc);
  return laneTotals(acc);
}

}  // namespace celc::detail
