#pragma once
// Internal: the per-row passes of the robust nullspace IRLS (robust_nullspace.cpp)
// over rows packed once as structure of arrays.
#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "constraint_rows.hpp"
#include "robust_loss.hpp"

namespace celc::detail {

/// The sums of one IRLS step: sum w_i a_i a_i^T (0..5) and sum w_i N_i^T N_i
/// (6..11), the distinct entries of each symmetric matrix in the order
/// xx yy zz xy xz yz.
using PackedSums = std::array<double, 12>;

/// The rows a_i^T v = 0 with normalisers N_i (|N_i v| makes a_i.v a geometric
/// residual), as structure of arrays: column j holds a_j (j = 0..2), then
/// N's rows one after the other (column 3 + 3 r + k = N(r, k)). N's third
/// row is left out when it is zero in every row (CELC's rows), so a pass
/// reads 9 columns instead of 12. Products are formed on the fly: the passes
/// are bound by reading the columns, not by arithmetic. Padded with zero
/// rows to a multiple of kLanes (a padded row has |N v| = 0: no weight).
class PackedRows {
 public:
  static constexpr size_t kLanes = 8;
  /// Empty, for up to `capacity` rows appended one by one. normal_rows = 2
  /// when the third row of every N is zero (CELC's rows), else 3.
  PackedRows(size_t capacity, int normal_rows);
  /// Packs and seals the rows (normal_rows from the rows).
  explicit PackedRows(const std::vector<ConstraintRow>& rows);

  /// Appends a row (beyond capacity: ignored, and false). With
  /// normalRows() = 2, N's third row is not stored: it must be zero.
  bool append(const Vec3& a, const Mat3& N);
  /// Appends a row whose N has the rows n0, n1 and a zero third row.
  bool append(const Vec3& a, const Vec3& n0, const Vec3& n1);
  /// Appends the CELC rows of m events of one cluster under a constant twist
  /// (ClusterRowTerms::row with the series coefficients), computed across
  /// the events in lanes: times t [s], bearings (fx, fy, fz) in the camera at
  /// t. Needs normalRows() = 2, room for m rows, and
  /// k.w2 (t - k.t_ref)^2 < kTwistSeriesLimit for every event. False (and
  /// nothing appended) when a row is not finite.
  bool appendTwistRows(const TwistRowConstants& k, const double* t, const double* fx,
                       const double* fy, const double* fz, size_t m);
  /// The same for m events inside one piece of a gyro-integrated model
  /// (GyroRowConstants), with |phi|^2 < kTwistSeriesLimit for every event;
  /// false (and nothing appended) otherwise or when a row is not finite.
  bool appendGyroRows(const GyroRowConstants& k, const double* t, const double* fx,
                      const double* fy, const double* fz, size_t m);
  /// Pads, forms the plain sums and the scale sample: once, after the last
  /// append and before any pass.
  void seal();

  size_t size() const { return n_; }  // rows, without the padding
  size_t paddedSize() const { return padded_; }
  int normalRows() const { return normal_rows_; }  // rows of N kept: 2 or 3
  const double* data() const { return data_.get(); }
  size_t stride() const { return stride_; }  // between columns [doubles]

  /// Plain sums (w_i = 1), the unweighted start.
  const PackedSums& plainSums() const { return plain_sums_; }
  /// Squared geometric residuals r^2 = (a.v)^2 / |N v|^2 of every row
  /// (r_degenerate^2 where |N v| = 0), into r2.
  void squaredResiduals(const Vec3& v, double r_degenerate, std::vector<double>& r2) const;
  /// Every step-th row, sealed.
  PackedRows strided(size_t step) const;
  /// The rows the robust scale is taken from: every floor(n / kScaleSample)-th,
  /// so 256 to 511 of them once n >= 256: enough for the Huber threshold
  /// (docs/method.md).
  const PackedRows& scaleSample() const { return sample_ ? *sample_ : *this; }
  static constexpr size_t kScaleSample = 256;

 private:
  void sealWithoutSample();
  size_t capacity_ = 0, n_ = 0, padded_ = 0, stride_ = 0;
  int normal_rows_ = 3;
  std::unique_ptr<double[]> data_;
  PackedSums plain_sums_{};
  std::shared_ptr<const PackedRows> sample_;  // null when every row is sampled
};

/// Sums with the IRLS weights of `loss` (Huber or Tukey; its scale thr on the
/// geometric residual r_i = d / sqrt(g2), d = a_i.v, g2 = |N_i v|^2) over
/// |N_i v|^2: Huber's w_i = min(1, thr / |r_i|) / g2 = min(1 / g2, thr /
/// sqrt(d^2 g2)); Tukey's w_i = (1 - r_i^2 / thr^2)^2 / g2 for |r_i| < thr,
/// else 0 (a row beyond thr has no influence at all); without a loss
/// (Type::None) w_i = 1. Rows with |N_i v| = 0 get no weight. One fused pass
/// over the columns in blocks of kLanes rows: lane l of every block adds to
/// its own partial sums (rows l, l + kLanes, ...), and the lanes' sums are
/// added in lane order, so the result does not depend on how the compiler
/// vectorises the lanes. loss.type is Huber, Tukey or None.
PackedSums weightedSums(const PackedRows& rows, const Vec3& v, const RobustLoss& loss);

}  // namespace celc::detail
