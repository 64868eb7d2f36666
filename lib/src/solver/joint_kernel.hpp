#pragma once
// Internal: the per-event passes of celc_ml's joint Levenberg-Marquardt
// (joint_refine.cpp) over its event terms packed as structure of arrays, so
// that the compiler forms several events at once (as irls_kernel does for
// the IRLS): the Gauss-Newton blocks of one cluster and its robust cost.
#include <cstddef>
#include <vector>

#include "celc/solver/celc_residual.hpp"
#include "robust_loss.hpp"

namespace celc::detail {

/// Event terms (EventTerm) as 27 columns: fp, the two rows of R_k^T, then De
/// and Ds row by row; with an acceleration, two more: q_e - q_k and
/// q_s - q_k, q(t) = (t - t_ref)^2 / 2 (celc_acc.hpp). Column j holds entry
/// j of every event, then at least kPadding zeros.
class JointColumns {
 public:
  static constexpr int kColumns = 27;
  static constexpr int kAccelerationColumns = 29;
  /// Which of the two kinds of spare buffers the storage comes from (and is
  /// given back to on destruction, thread_buffer.hpp): a problem's full
  /// columns and its strided ones are held at once.
  enum class Spare { Strided, Full };
  explicit JointColumns(Spare spare = Spare::Strided);
  ~JointColumns();
  JointColumns(const JointColumns&) = delete;
  JointColumns& operator=(const JointColumns&) = delete;
  /// Every step-th event of each cluster c, terms[begin[c], begin[c + 1]);
  /// strided_begin gets the clusters' ranges in the columns. With `dq`
  /// (per term: q_e - q_k, q_s - q_k), the acceleration's columns too.
  void assign(const std::vector<EventTerm>& terms, const std::vector<size_t>& begin, size_t step,
              std::vector<size_t>& strided_begin, const std::vector<Eigen::Vector2d>* dq = nullptr);
  /// The same from the rows of `full` (begin: its clusters' ranges): every
  /// step-th row of each cluster, the values copied exactly.
  void assignStrided(const JointColumns& full, const std::vector<size_t>& begin, size_t step,
                     std::vector<size_t>& strided_begin);
  /// Empty columns with room for up to max_rows events, filled by appendRow
  /// (so that a problem's terms are written once, with no array of
  /// structures).
  void startRows(size_t max_rows, bool acceleration);
  /// Appends an event's term (and with an acceleration dq = (q_e - q_k,
  /// q_s - q_k)) as the next row; at most startRows' max_rows rows.
  void appendRow(const EventTerm& e, const Eigen::Vector2d& dq = Eigen::Vector2d::Zero());
  /// The term of row i, the values as stored.
  EventTerm term(size_t i) const;
  /// Zero rows after the events, so that a pass may read a whole block of
  /// lanes past the last one.
  static constexpr size_t kPadding = 8;
  size_t size() const { return n_; }
  const double* data() const { return data_.data(); }
  size_t stride() const { return stride_; }  ///< between columns [doubles], at least size() + kPadding
  bool hasAcceleration() const { return acceleration_; }

 private:
  void writeRow(size_t row, const EventTerm& e, const Eigen::Vector2d& dq);
  /// Zeroed columns for every step-th event of each cluster [begin[c],
  /// begin[c + 1]), their ranges into strided_begin; size() rows.
  void layOut(const std::vector<size_t>& begin, size_t step, std::vector<size_t>& strided_begin, bool acceleration);
  Spare spare_;
  size_t n_ = 0;
  size_t stride_ = kPadding;
  bool acceleration_ = false;
  std::vector<double> data_;
};

/// One cluster's Gauss-Newton sums at (v, m1, m3) over the events
/// begin .. end - 1 of the columns: with d the event distance [px]
/// (eventDistance), r the loss's residual in the reweighted form
/// (robust_loss.hpp: Huber's square root, Cauchy's and Tukey's with the
/// weights frozen at the point of linearisation; scale in px), dr/dd its
/// slope, and
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
                              const double* B3, double focal, const RobustLoss& loss);

/// The same sums with a constant acceleration a (columns with the
/// acceleration's): the camera's position P(t) v + q(t) a, so that
/// u.v -> u.v + (q_e - q_k) m3.a and s.v -> s.v + (q_s - q_k) m1.a in the
/// event distance. The global block is g = (v's tangent, a): jg = slope
/// (Bv^T dd/dv, dd/da), G = sum jg jg^T (upper triangle, row by row, 15),
/// bg = sum jg r, W = sum jg jc^T (5 x 4, row by row); U and bc as above.
struct JointAccelerationSums {
  double G[15], bg[5], U[10], W[20], bc[4];
};
JointAccelerationSums jointAccelerationSums(const JointColumns& columns, size_t begin, size_t end,
                                            const Vec3& v, const Vec3& a, const Vec3& m1, const Vec3& m3,
                                            const double* Bv, const double* B1, const double* B3, double focal,
                                            const RobustLoss& loss);

/// sum of the Huber rho(d) = d^2 (|d| <= delta), 2 delta |d| - delta^2
/// (beyond) over the same events; +inf when a distance is not finite. With
/// `a` (columns with the acceleration's), the distances under it.
double jointHuberCost(const JointColumns& columns, size_t begin, size_t end, const Vec3& v, const Vec3& m1,
                      const Vec3& m3, double focal, double delta, const Vec3* a = nullptr);

/// The event distances d [px] of the same events into out[0 .. end - begin),
/// NaN where the transferred line has no image direction; `a` as above.
void jointDistances(const JointColumns& columns, size_t begin, size_t end, const Vec3& v, const Vec3& m1,
                    const Vec3& m3, double focal, double* out, const Vec3* a = nullptr);

}  // namespace celc::detail
