#pragma once
// Internal: the per-event passes of celc_ml's joint Levenberg-Marquardt
// (joint_refine.cpp) over its event terms packed as structure of arrays, so
// that the compiler forms several events at once (as irls_kernel does for
// the IRLS): the Gauss-Newton blocks of one cluster and its robust cost.
#include <cstddef>
#include <vector>

#include "celc/solver/celc_residual.hpp"

namespace celc::detail {

/// Event terms (EventTerm) as 27 columns: fp, the two rows of R_k^T, then De
/// and Ds row by row; column j holds entry j of every event, then kPadding
/// zeros.
class JointColumns {
 public:
  static constexpr int kColumns = 27;
  /// The storage is the thread's spare columns, given back on destruction
  /// (thread_buffer.hpp).
  JointColumns();
  ~JointColumns();
  JointColumns(const JointColumns&) = delete;
  JointColumns& operator=(const JointColumns&) = delete;
  /// Every step-th event of each cluster c, terms[begin[c], begin[c + 1]);
  /// strided_begin gets the clusters' ranges in the columns.
  void assign(const std::vector<EventTerm>& terms, const std::vector<size_t>& begin, size_t step,
              std::vector<size_t>& strided_begin);
  /// Zero rows after the events, so that a pass may read a whole block of
  /// lanes past the last one.
  static constexpr size_t kPadding = 8;
  size_t size() const { return n_; }
  const double* data() const { return data_.data(); }
  size_t stride() const { return n_ + kPadding; }  ///< between columns [doubles]

 private:
  size_t n_ = 0;
  std::vector<double> data_;
};

/// The loss of a pass: Huber with threshold `scale` [px], or the Cauchy loss
/// or Tukey's biweight with scale c [px] by iteratively reweighted steps
/// (weights frozen at the point of linearisation: r = d / sqrt(1 + d^2 / c^2),
/// r = (1 - d^2 / c^2) d within c and 0 beyond).
enum class JointLossKind { Huber, Cauchy, Tukey };

/// One cluster's Gauss-Newton sums at (v, m1, m3) over the events
/// begin .. end - 1 of the columns: with d the event distance [px]
/// (eventDistance), r the loss's square-root residual, dr/dd its slope, and
/// the tangent bases Bv, B1, B3 (3 x 2, column-major), jv = slope Bv^T dd/dv
/// and jc = slope (B1^T dd/dm1, B3^T dd/dm3):
///   V = sum jv jv^T (xx, xy, yy), bv = sum jv r,
///   U = sum jc jc^T (upper triangle, row by row), W = sum jv jc^T (row by
///   row), bc = sum jc r.
/// Events whose distance is not finite add nothing.
struct JointBlockSums {
  double V[3], bv[2], U[10], W[8], bc[4];
};
JointBlockSums jointBlockSums(const JointColumns& columns, size_t begin, size_t end, const Vec3& v,
                              const Vec3& m1, const Vec3& m3, const double* Bv, const double* B1,
                              const double* B3, double focal, JointLossKind loss, double scale);

/// sum of the Huber rho(d) = d^2 (|d| <= delta), 2 delta |d| - delta^2
/// (beyond) over the same events; +inf when a distance is not finite.
double jointHuberCost(const JointColumns& columns, size_t begin, size_t end, const Vec3& v, const Vec3& m1,
                      const Vec3& m3, double focal, double delta);

/// The event distances d [px] of the same events into out[0 .. end - begin),
/// NaN where the transferred line has no image direction.
void jointDistances(const JointColumns& columns, size_t begin, size_t end, const Vec3& v, const Vec3& m1,
                    const Vec3& m3, double focal, double* out);

}  // namespace celc::detail
