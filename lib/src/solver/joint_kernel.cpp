// celc_ml's per-event passes: plain loops over the event columns that the
// compiler vectorises across the lanes of a block (`#pragma omp simd`),
// compiled like the IRLS passes (isa_clones.hpp, CMakeLists.txt).
#include "joint_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "isa_clones.hpp"
#include "thread_buffer.hpp"

namespace celc::detail {

namespace {
/// The spares for the full columns (the strided ones use JointColumns').
struct FullColumnsSpare;
}  // namespace

JointColumns::JointColumns(Spare spare) : spare_(spare) {
  if (spare_ == Spare::Full)
    borrowSpareVector<FullColumnsSpare>(data_);
  else
    borrowSpareVector<JointColumns>(data_);
}

JointColumns::~JointColumns() {
  if (spare_ == Spare::Full)
    returnSpareVector<FullColumnsSpare>(data_);
  else
    returnSpareVector<JointColumns>(data_);
}

void JointColumns::writeRow(size_t row, const EventTerm& e, const Eigen::Vector2d& dq) {
  const size_t s = stride_;
  double* c = data_.data() + row;
  for (int j = 0; j < 3; ++j) {
    c[static_cast<size_t>(j) * s] = e.fp(j);
    c[static_cast<size_t>(3 + j) * s] = e.Rt01(0, j);
    c[static_cast<size_t>(6 + j) * s] = e.Rt01(1, j);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      c[static_cast<size_t>(9 + 3 * i + j) * s] = e.De(i, j);
      c[static_cast<size_t>(18 + 3 * i + j) * s] = e.Ds(i, j);
    }
  if (acceleration_) {
    c[static_cast<size_t>(27) * s] = dq(0);
    c[static_cast<size_t>(28) * s] = dq(1);
  }
}

void JointColumns::layOut(const std::vector<size_t>& begin, size_t step, std::vector<size_t>& strided_begin,
                          bool acceleration) {
  strided_begin.assign(1, 0);
  for (size_t c = 0; c + 1 < begin.size(); ++c)
    strided_begin.push_back(strided_begin.back() + (begin[c + 1] - begin[c] + step - 1) / step);
  startRows(strided_begin.back(), acceleration);
  n_ = strided_begin.back();
}

void JointColumns::assign(const std::vector<EventTerm>& terms, const std::vector<size_t>& begin, size_t step,
                          std::vector<size_t>& strided_begin, const std::vector<Eigen::Vector2d>* dq) {
  step = std::max<size_t>(1, step);
  layOut(begin, step, strided_begin, dq != nullptr);
  size_t row = 0;
  for (size_t cl = 0; cl + 1 < begin.size(); ++cl)
    for (size_t k = begin[cl]; k < begin[cl + 1]; k += step, ++row)
      writeRow(row, terms[k], acceleration_ ? (*dq)[k] : Eigen::Vector2d::Zero().eval());
}

void JointColumns::assignStrided(const JointColumns& full, const std::vector<size_t>& begin, size_t step,
                                 std::vector<size_t>& strided_begin) {
  step = std::max<size_t>(1, step);
  layOut(begin, step, strided_begin, full.acceleration_);
  const size_t columns = static_cast<size_t>(acceleration_ ? kAccelerationColumns : kColumns);
  for (size_t j = 0; j < columns; ++j) {
    const double* from = full.data_.data() + j * full.stride_;
    double* to = data_.data() + j * stride_;
    size_t row = 0;
    for (size_t cl = 0; cl + 1 < begin.size(); ++cl)
      for (size_t k = begin[cl]; k < begin[cl + 1]; k += step) to[row++] = from[k];
  }
}

void JointColumns::startRows(size_t max_rows, bool acceleration) {
  n_ = 0;
  stride_ = max_rows + kPadding;
  acceleration_ = acceleration;
  const size_t columns = static_cast<size_t>(acceleration_ ? kAccelerationColumns : kColumns);
  reserveWithHeadroom(data_, columns * stride_);
  data_.assign(columns * stride_, 0.0);
}

void JointColumns::appendRow(const EventTerm& e, const Eigen::Vector2d& dq) {
  if (n_ + kPadding >= stride_) throw std::logic_error("JointColumns::appendRow: more rows than startRows allowed");
  writeRow(n_, e, dq);
  ++n_;
}

EventTerm JointColumns::term(size_t i) const {
  EventTerm e;
  const size_t s = stride_;
  const double* c = data_.data() + i;
  for (int j = 0; j < 3; ++j) {
    e.fp(j) = c[static_cast<size_t>(j) * s];
    e.Rt01(0, j) = c[static_cast<size_t>(3 + j) * s];
    e.Rt01(1, j) = c[static_cast<size_t>(6 + j) * s];
  }
  for (int i2 = 0; i2 < 3; ++i2)
    for (int j = 0; j < 3; ++j) {
      e.De(i2, j) = c[static_cast<size_t>(9 + 3 * i2 + j) * s];
      e.Ds(i2, j) = c[static_cast<size_t>(18 + 3 * i2 + j) * s];
    }
  return e;
}

namespace {
constexpr int kSums = 27;
constexpr size_t kLanes = 8;

// One event's distance d [px] and, with kGradients, dd/dv, dd/dm1, dd/dm3
// (and dd/da with kAcceleration): eventDistance (celc_residual.hpp) on the
// columns c (stride s) at index i, with kAcceleration the camera's position
// P(t) v + q(t) a (columns 27, 28: q_e - q_k, q_s - q_k). ok is false where
// the transferred line has no image direction.
struct Distance {
  double d;
  bool ok;
  double gv[3], g1[3], g3[3];  // with kGradients
  double ga[3];                // with kGradients and kAcceleration
};
template <bool kGradients, bool kAcceleration = false>
CELC_PASS_INLINE Distance distance(const double* c, size_t s, size_t i, const double* v, const double* m1,
                                   const double* m3, double focal, const double* a = nullptr) {
  const double* e = c + i;  // captured by value (above)
  const auto at = [e, s](int j) { return e[static_cast<size_t>(j) * s]; };
  Distance out;
  double u[3], sv3[3];  // u = De^T m3, s = Ds^T m1
  #pragma GCC unroll 4
  for (int j = 0; j < 3; ++j) {
    u[j] = at(9 + j) * m3[0] + at(12 + j) * m3[1] + at(15 + j) * m3[2];
    sv3[j] = at(18 + j) * m1[0] + at(21 + j) * m1[1] + at(24 + j) * m1[2];
  }
  double uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  double sv = sv3[0] * v[0] + sv3[1] * v[1] + sv3[2] * v[2];
  double dqe = 0.0, dqs = 0.0;
  if (kAcceleration) {
    dqe = at(27), dqs = at(28);
    uv += dqe * (m3[0] * a[0] + m3[1] * a[1] + m3[2] * a[2]);
    sv += dqs * (m1[0] * a[0] + m1[1] * a[1] + m1[2] * a[2]);
  }
  double l[3];
  #pragma GCC unroll 4
  for (int j = 0; j < 3; ++j) l[j] = m1[j] * uv - m3[j] * sv;
  const double ga = at(3) * l[0] + at(4) * l[1] + at(5) * l[2];
  const double gb = at(6) * l[0] + at(7) * l[1] + at(8) * l[2];
  const double gn_raw = std::sqrt(ga * ga + gb * gb);
  out.ok = gn_raw > 1e-300;
  const double gn = out.ok ? gn_raw : 1.0;
  const double num = at(0) * l[0] + at(1) * l[1] + at(2) * l[2];
  out.d = focal * num / gn;
  if (kGradients) {
    // dl = dd/dl = focal (fp / |g| - num (R01^T g) / |g|^3), then the chain
    // rule through l = m1 (u.v) - m3 (s.v).
    const double k3 = num / (gn * gn * gn);
    const double dl0 = focal * (at(0) / gn - k3 * (at(3) * ga + at(6) * gb));
    const double dl1 = focal * (at(1) / gn - k3 * (at(4) * ga + at(7) * gb));
    const double dl2 = focal * (at(2) / gn - k3 * (at(5) * ga + at(8) * gb));
    const double m1dl = m1[0] * dl0 + m1[1] * dl1 + m1[2] * dl2;
    const double m3dl = m3[0] * dl0 + m3[1] * dl1 + m3[2] * dl2;
    // (Ds v)_j and (De v)_j (with an acceleration, Ds v + dqs a and De v + dqe a).
    double dsv0 = at(18) * v[0] + at(19) * v[1] + at(20) * v[2];
    double dsv1 = at(21) * v[0] + at(22) * v[1] + at(23) * v[2];
    double dsv2 = at(24) * v[0] + at(25) * v[1] + at(26) * v[2];
    double dev0 = at(9) * v[0] + at(10) * v[1] + at(11) * v[2];
    double dev1 = at(12) * v[0] + at(13) * v[1] + at(14) * v[2];
    double dev2 = at(15) * v[0] + at(16) * v[1] + at(17) * v[2];
    if (kAcceleration) {
      dsv0 += dqs * a[0], dsv1 += dqs * a[1], dsv2 += dqs * a[2];
      dev0 += dqe * a[0], dev1 += dqe * a[1], dev2 += dqe * a[2];
      // dl/da = dqe m1 m3^T - dqs m3 m1^T.
      out.ga[0] = dqe * m3[0] * m1dl - dqs * m1[0] * m3dl;
      out.ga[1] = dqe * m3[1] * m1dl - dqs * m1[1] * m3dl;
      out.ga[2] = dqe * m3[2] * m1dl - dqs * m1[2] * m3dl;
    }
    out.gv[0] = u[0] * m1dl - sv3[0] * m3dl, out.gv[1] = u[1] * m1dl - sv3[1] * m3dl;
    out.gv[2] = u[2] * m1dl - sv3[2] * m3dl;
    out.g1[0] = uv * dl0 - dsv0 * m3dl, out.g1[1] = uv * dl1 - dsv1 * m3dl, out.g1[2] = uv * dl2 - dsv2 * m3dl;
    out.g3[0] = dev0 * m1dl - sv * dl0, out.g3[1] = dev1 * m1dl - sv * dl1, out.g3[2] = dev2 * m1dl - sv * dl2;
  }
  return out;
}

// The sums of jointBlockSums (in its order: V, bv, U, W, bc) over the
// events begin .. begin + count - 1, in blocks of kLanes events whose lanes
// the compiler forms together, each lane with its own accumulators. Values
// stay in locals returned by value: through pointers (output arguments, a
// struct's arrays, a lambda holding the index by reference) the compiler
// kept them in memory per lane and the loop ran scalar.
template <RobustLoss::Type kLoss>
CELC_PASS_INLINE void blockSums(const double* c, size_t s, size_t begin, size_t count,
                                const double* v, const double* m1, const double* m3, const double* Bv,
                                const double* B1, const double* B3, double focal, double scale,
                                double* out) {
  // Local copies: loads inside the selects below could not be speculated
  // from the pointers (they might trap), which would keep the loop scalar.
  double vb[6], b1[6], b3[6];
  std::copy(Bv, Bv + 6, vb), std::copy(B1, B1 + 6, b1), std::copy(B3, B3 + 6, b3);
  // The last block reads into the next cluster's events or the columns'
  // padding, masked out.
  double acc[kSums][kLanes] = {};
  for (size_t b = 0; b < count; b += kLanes) {
#pragma omp simd
    for (size_t l = 0; l < kLanes; ++l) {
      const size_t i = begin + b + l;
      const bool in = b + l < count;
      const Distance e = distance<true>(c, s, i, v, m1, m3, focal);
      const double d = e.d;
      const bool ok = e.ok;
      const ReweightedRoot root = reweighted<kLoss>(d, scale);
      const double r = root.r, slope = root.slope;
      const bool use = in & ok & std::isfinite(d);
      const double w = use ? slope : 0.0, rr = use ? r : 0.0;
      double jv[2], jc[4];
      #pragma GCC unroll 4
      for (int a = 0; a < 2; ++a) {
        jv[a] = w * (vb[3 * a] * e.gv[0] + vb[3 * a + 1] * e.gv[1] + vb[3 * a + 2] * e.gv[2]);
        jc[a] = w * (b1[3 * a] * e.g1[0] + b1[3 * a + 1] * e.g1[1] + b1[3 * a + 2] * e.g1[2]);
        jc[2 + a] = w * (b3[3 * a] * e.g3[0] + b3[3 * a + 1] * e.g3[1] + b3[3 * a + 2] * e.g3[2]);
      }
      // A non-finite gradient of a used event would poison the sums, as it
      // did the former per-event loop's; unused events add exact zeros.
      #pragma GCC unroll 4
      for (int a = 0; a < 2; ++a) jv[a] = use ? jv[a] : 0.0;
      #pragma GCC unroll 4
      for (int a = 0; a < 4; ++a) jc[a] = use ? jc[a] : 0.0;
      acc[0][l] += jv[0] * jv[0], acc[1][l] += jv[0] * jv[1], acc[2][l] += jv[1] * jv[1];
      acc[3][l] += jv[0] * rr, acc[4][l] += jv[1] * rr, acc[5][l] += jc[0] * jc[0];
      acc[6][l] += jc[0] * jc[1], acc[7][l] += jc[0] * jc[2], acc[8][l] += jc[0] * jc[3];
      acc[9][l] += jc[1] * jc[1], acc[10][l] += jc[1] * jc[2], acc[11][l] += jc[1] * jc[3];
      acc[12][l] += jc[2] * jc[2], acc[13][l] += jc[2] * jc[3], acc[14][l] += jc[3] * jc[3];
      acc[15][l] += jv[0] * jc[0], acc[16][l] += jv[0] * jc[1], acc[17][l] += jv[0] * jc[2];
      acc[18][l] += jv[0] * jc[3], acc[19][l] += jv[1] * jc[0], acc[20][l] += jv[1] * jc[1];
      acc[21][l] += jv[1] * jc[2], acc[22][l] += jv[1] * jc[3], acc[23][l] += jc[0] * rr;
      acc[24][l] += jc[1] * rr, acc[25][l] += jc[2] * rr, acc[26][l] += jc[3] * rr;
    }
  }
  double sums[kSums] = {};
  for (int k = 0; k < kSums; ++k)
    for (size_t l = 0; l < kLanes; ++l) sums[k] += acc[k][l];
  std::copy(sums, sums + kSums, out);
}

CELC_ISA_CLONES void blockSumsTukey(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                    const double* m1, const double* m3, const double* Bv, const double* B1,
                                    const double* B3, double focal, double scale, double* out) {
  blockSums<RobustLoss::Type::Tukey>(c, s, begin, count, v, m1, m3, Bv, B1, B3, focal, scale, out);
}

CELC_ISA_CLONES void blockSumsHuber(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                    const double* m1, const double* m3, const double* Bv, const double* B1,
                                    const double* B3, double focal, double scale, double* out) {
  blockSums<RobustLoss::Type::Huber>(c, s, begin, count, v, m1, m3, Bv, B1, B3, focal, scale, out);
}
CELC_ISA_CLONES void blockSumsCauchy(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                     const double* m1, const double* m3, const double* Bv, const double* B1,
                                     const double* B3, double focal, double scale, double* out) {
  blockSums<RobustLoss::Type::Cauchy>(c, s, begin, count, v, m1, m3, Bv, B1, B3, focal, scale, out);
}

// The sums of jointAccelerationSums (G, bg, U, W, bc), laid out as
// blockSums' with the global block g = (v's tangent, a) of 5.
constexpr int kAccelerationSums = 15 + 5 + 10 + 20 + 4;
template <RobustLoss::Type kLoss>
CELC_PASS_INLINE void accelerationSums(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                       const double* a, const double* m1, const double* m3, const double* Bv,
                                       const double* B1, const double* B3, double focal, double scale,
                                       double* out) {
  double vb[6], b1[6], b3[6], av[3];
  std::copy(Bv, Bv + 6, vb), std::copy(B1, B1 + 6, b1), std::copy(B3, B3 + 6, b3), std::copy(a, a + 3, av);
  double acc[kAccelerationSums][kLanes] = {};
  for (size_t b = 0; b < count; b += kLanes) {
#pragma omp simd
    for (size_t l = 0; l < kLanes; ++l) {
      const size_t i = begin + b + l;
      const bool in = b + l < count;
      const Distance e = distance<true, true>(c, s, i, v, m1, m3, focal, av);
      const ReweightedRoot root = reweighted<kLoss>(e.d, scale);
      const bool use = in & e.ok & std::isfinite(e.d);
      const double w = use ? root.slope : 0.0, rr = use ? root.r : 0.0;
      double jg[5], jc[4];
      #pragma GCC unroll 4
      for (int k = 0; k < 2; ++k) {
        jg[k] = w * (vb[3 * k] * e.gv[0] + vb[3 * k + 1] * e.gv[1] + vb[3 * k + 2] * e.gv[2]);
        jc[k] = w * (b1[3 * k] * e.g1[0] + b1[3 * k + 1] * e.g1[1] + b1[3 * k + 2] * e.g1[2]);
        jc[2 + k] = w * (b3[3 * k] * e.g3[0] + b3[3 * k + 1] * e.g3[1] + b3[3 * k + 2] * e.g3[2]);
      }
      #pragma GCC unroll 4
      for (int k = 0; k < 3; ++k) jg[2 + k] = w * e.ga[k];
      #pragma GCC unroll 8
      for (int k = 0; k < 5; ++k) jg[k] = use ? jg[k] : 0.0;
      #pragma GCC unroll 4
      for (int k = 0; k < 4; ++k) jc[k] = use ? jc[k] : 0.0;
      int n = 0;
      #pragma GCC unroll 8
      for (int p = 0; p < 5; ++p)
        #pragma GCC unroll 8
        for (int q = p; q < 5; ++q) acc[n++][l] += jg[p] * jg[q];
      #pragma GCC unroll 8
      for (int p = 0; p < 5; ++p) acc[n++][l] += jg[p] * rr;
      #pragma GCC unroll 4
      for (int p = 0; p < 4; ++p)
        #pragma GCC unroll 4
        for (int q = p; q < 4; ++q) acc[n++][l] += jc[p] * jc[q];
      #pragma GCC unroll 8
      for (int p = 0; p < 5; ++p)
        #pragma GCC unroll 4
        for (int q = 0; q < 4; ++q) acc[n++][l] += jg[p] * jc[q];
      #pragma GCC unroll 4
      for (int p = 0; p < 4; ++p) acc[n++][l] += jc[p] * rr;
    }
  }
  double sums[kAccelerationSums] = {};
  for (int k = 0; k < kAccelerationSums; ++k)
    for (size_t l = 0; l < kLanes; ++l) sums[k] += acc[k][l];
  std::copy(sums, sums + kAccelerationSums, out);
}

CELC_ISA_CLONES void accelerationSumsHuber(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                           const double* a, const double* m1, const double* m3, const double* Bv,
                                           const double* B1, const double* B3, double focal, double scale,
                                           double* out) {
  accelerationSums<RobustLoss::Type::Huber>(c, s, begin, count, v, a, m1, m3, Bv, B1, B3, focal, scale, out);
}
CELC_ISA_CLONES void accelerationSumsCauchy(const double* c, size_t s, size_t begin, size_t count,
                                            const double* v, const double* a, const double* m1, const double* m3,
                                            const double* Bv, const double* B1, const double* B3, double focal,
                                            double scale, double* out) {
  accelerationSums<RobustLoss::Type::Cauchy>(c, s, begin, count, v, a, m1, m3, Bv, B1, B3, focal, scale, out);
}
CELC_ISA_CLONES void accelerationSumsTukey(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                           const double* a, const double* m1, const double* m3, const double* Bv,
                                           const double* B1, const double* B3, double focal, double scale,
                                           double* out) {
  accelerationSums<RobustLoss::Type::Tukey>(c, s, begin, count, v, a, m1, m3, Bv, B1, B3, focal, scale, out);
}

// sum rho(d) over the events begin .. begin + count - 1, and the number of
// them whose distance is not finite.
template <bool kAcceleration>
CELC_PASS_INLINE void huberCostPass(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                    const double* m1, const double* m3, double focal, double delta, const double* a,
                                    double* out) {
  double total = 0.0, bad = 0.0;
#pragma omp simd reduction(+ : total, bad)
  for (size_t k = 0; k < count; ++k) {
    const size_t i = begin + k;
    const Distance e = distance<false, kAcceleration>(c, s, i, v, m1, m3, focal, a);
    const double d = e.d;
    const bool ok = e.ok;
    const double a = std::abs(d);
    const double rho = a <= delta ? d * d : 2.0 * delta * a - delta * delta;
    const bool good = ok & std::isfinite(d);
    total += good ? rho : 0.0;
    bad += good ? 0.0 : 1.0;
  }
  out[0] = total, out[1] = bad;
}

CELC_ISA_CLONES void huberCost(const double* c, size_t s, size_t begin, size_t count, const double* v,
                               const double* m1, const double* m3, double focal, double delta, double* out) {
  huberCostPass<false>(c, s, begin, count, v, m1, m3, focal, delta, nullptr, out);
}
CELC_ISA_CLONES void huberCostAcceleration(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                           const double* m1, const double* m3, double focal, double delta,
                                           const double* a, double* out) {
  huberCostPass<true>(c, s, begin, count, v, m1, m3, focal, delta, a, out);
}

template <bool kAcceleration>
CELC_PASS_INLINE void distancesPass(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                    const double* m1, const double* m3, double focal, const double* a, double* out) {
#pragma omp simd
  for (size_t k = 0; k < count; ++k) {
    const Distance e = distance<false, kAcceleration>(c, s, begin + k, v, m1, m3, focal, a);
    out[k] = e.ok ? e.d : std::numeric_limits<double>::quiet_NaN();
  }
}
CELC_ISA_CLONES void distances(const double* c, size_t s, size_t begin, size_t count, const double* v,
                               const double* m1, const double* m3, double focal, double* out) {
  distancesPass<false>(c, s, begin, count, v, m1, m3, focal, nullptr, out);
}
CELC_ISA_CLONES void distancesAcceleration(const double* c, size_t s, size_t begin, size_t count, const double* v,
                                           const double* m1, const double* m3, double focal, const double* a,
                                           double* out) {
  distancesPass<true>(c, s, begin, count, v, m1, m3, focal, a, out);
}

}  // namespace

JointBlockSums jointBlockSums(const JointColumns& columns, size_t begin, size_t end, const Vec3& v,
                              const Vec3& m1, const Vec3& m3, const double* Bv,
                              const double* B1, const double* B3, double focal, const RobustLoss& loss) {
  const double scale = loss.scale;
  double total[kSums];
  const double vv[3] = {v.x(), v.y(), v.z()}, a1[3] = {m1.x(), m1.y(), m1.z()},
               a3[3] = {m3.x(), m3.y(), m3.z()};
  const size_t count = end > begin ? end - begin : 0;
  if (loss.type == RobustLoss::Type::Huber)
    blockSumsHuber(columns.data(), columns.stride(), begin, count, vv, a1, a3, Bv, B1, B3, focal, scale, total);
  else if (loss.type == RobustLoss::Type::Cauchy)
    blockSumsCauchy(columns.data(), columns.stride(), begin, count, vv, a1, a3, Bv, B1, B3, focal, scale, total);
  else
    blockSumsTukey(columns.data(), columns.stride(), begin, count, vv, a1, a3, Bv, B1, B3, focal, scale, total);
  JointBlockSums out;
  std::copy(total, total + 3, out.V);
  std::copy(total + 3, total + 5, out.bv);
  std::copy(total + 5, total + 15, out.U);
  std::copy(total + 15, total + 23, out.W);
  std::copy(total + 23, total + 27, out.bc);
  return out;
}

JointAccelerationSums jointAccelerationSums(const JointColumns& columns, size_t begin, size_t end,
                                            const Vec3& v, const Vec3& a, const Vec3& m1, const Vec3& m3,
                                            const double* Bv, const double* B1, const double* B3, double focal,
                                            const RobustLoss& loss) {
  const double scale = loss.scale;
  double total[kAccelerationSums];
  const double vv[3] = {v.x(), v.y(), v.z()}, aa[3] = {a.x(), a.y(), a.z()}, a1[3] = {m1.x(), m1.y(), m1.z()},
               a3[3] = {m3.x(), m3.y(), m3.z()};
  const size_t count = end > begin ? end - begin : 0;
  const double* c = columns.data();
  const size_t s = columns.stride();
  if (loss.type == RobustLoss::Type::Huber)
    accelerationSumsHuber(c, s, begin, count, vv, aa, a1, a3, Bv, B1, B3, focal, scale, total);
  else if (loss.type == RobustLoss::Type::Cauchy)
    accelerationSumsCauchy(c, s, begin, count, vv, aa, a1, a3, Bv, B1, B3, focal, scale, total);
  else
    accelerationSumsTukey(c, s, begin, count, vv, aa, a1, a3, Bv, B1, B3, focal, scale, total);
  JointAccelerationSums out;
  std::copy(total, total + 15, out.G);
  std::copy(total + 15, total + 20, out.bg);
  std::copy(total + 20, total + 30, out.U);
  std::copy(total + 30, total + 50, out.W);
  std::copy(total + 50, total + 54, out.bc);
  return out;
}

double jointHuberCost(const JointColumns& columns, size_t begin, size_t end, const Vec3& v, const Vec3& m1,
                      const Vec3& m3, double focal, double delta, const Vec3* a) {
  const double vv[3] = {v.x(), v.y(), v.z()}, a1[3] = {m1.x(), m1.y(), m1.z()},
               a3[3] = {m3.x(), m3.y(), m3.z()};
  double out[2];
  const size_t count = end > begin ? end - begin : 0;
  if (a) {
    const double aa[3] = {a->x(), a->y(), a->z()};
    huberCostAcceleration(columns.data(), columns.stride(), begin, count, vv, a1, a3, focal, delta, aa, out);
  } else {
    huberCost(columns.data(), columns.stride(), begin, count, vv, a1, a3, focal, delta, out);
  }
  return out[1] > 0.0 ? std::numeric_limits<double>::infinity() : out[0];
}

void jointDistances(const JointColumns& columns, size_t begin, size_t end, const Vec3& v, const Vec3& m1,
                    const Vec3& m3, double focal, double* out, const Vec3* a) {
  const double vv[3] = {v.x(), v.y(), v.z()}, a1[3] = {m1.x(), m1.y(), m1.z()},
               a3[3] = {m3.x(), m3.y(), m3.z()};
  const size_t count = end > begin ? end - begin : 0;
  if (a) {
    const double aa[3] = {a->x(), a->y(), a->z()};
    distancesAcceleration(columns.data(), columns.stride(), begin, count, vv, a1, a3, focal, aa, out);
  } else {
    distances(columns.data(), columns.stride(), begin, count, vv, a1, a3, focal, out);
  }
}

}  // namespace celc::detail
