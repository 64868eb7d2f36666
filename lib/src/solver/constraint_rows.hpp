#pragma once
// Internal: the linear constraint rows of CELC and CE3LC, and the frames of a
// window's clusters that every method and the sign test share. All vectors in
// the reference frame of the motion model unless said otherwise.
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/geometry/so3.hpp"
#include "celc/solver/celc_residual.hpp"
#include "celc/core/observations.hpp"

namespace celc::detail {

/// One linear constraint a^T v = 0 with its normaliser: the geometric residual
/// is a^T v / |N v| (N's rows are the components that make the line's norm).
struct ConstraintRow {
  Vec3 a;
  Mat3 N;
};

/// The CELC row of one event (time t, bearing f = (x, y, 1) in the camera at t):
///   u = (P_e - P_k)^T m3,  s = (P_s - P_k)^T m1,
///   B_ref = m1 u^T - m3 s^T,  a = B_ref^T (R_k f),  N = first two rows of R_k^T B_ref, third 0,
/// so that a^T v / |N v| is the distance of (x, y) to the transferred line in
/// normalised units (celc_residual.hpp's d / focal).
ConstraintRow celcRow(const ClusterFrame& frame, const MotionModel& motion, double t, const Vec3& f);

/// What an event's CELC row and its cheirality vote need, from its pose
/// (R_k, P_k): with g_i = R_k^T m_i (the lines' normals in the camera at t_k),
/// u = (P_e - P_k)^T m3 and s = (P_s - P_k)^T m1 (so B_ref = m1 u^T - m3 s^T),
///   a = B_ref^T R_k f = (g1.f) u - (g3.f) s,   N_r = g1_r u - g3_r s  (r = 0, 1),
/// and the transferred line in the camera at t_k is R_k^T B_ref v = g1 (u.v) - g3 (s.v).
struct EventLineTerms {
  Vec3 g1, g3, u, s;
};

/// A cluster's event-independent terms of its CELC rows under a constant
/// twist w about t_ref (reference frame): m1, m3, u0 = P_e^T m3, s0 = P_s^T m1,
/// w x m_i, w x (w x m_i) and w2 = |w|^2. With tau = t - t_ref, phi = w tau and
/// the SO(3) coefficients A = sin|phi| / |phi|, B = (1 - cos|phi|) / |phi|^2,
/// C = (|phi| - sin|phi|) / |phi|^3 (R = I + A W + B W^2,
/// P = tau (I + B W + C W^2), W = [phi]_x):
///   g_i = R^T m_i = m_i - A tau (w x m_i) + B tau^2 w x (w x m_i),
///   P^T m = tau m - B tau^2 (w x m) + C tau^3 w x (w x m).
struct TwistRowConstants {
  double t_ref = 0.0, w2 = 0.0;
  Vec3 m1, m3, u0, s0, wm1, wm3, wwm1, wwm3;
};

/// A cluster's terms of its CELC rows over one piece of a gyro-integrated
/// model (MotionModel::RotationPiece: R = R0 exp(phi), phi = (w0 + h dt) dt,
/// dt = t - t0). With m_i' = R0^T m_i, the SO(3) coefficients A, B, C of phi
/// and y x z the cross product:
///   g_i = m_i' - A phi x m_i' + B phi x (phi x m_i'),
///   u = U - dt p3,  s = S - dt p1, where
///   body velocity:      p_i = m_i' - B phi x m_i' + C phi x (phi x m_i'),
///                       U = u0 - P0^T m3, S = s0 - P0^T m1;
///   reference velocity: p_i = m_i, U = u0 - (t0 - t_ref) m3, S = s0 - (t0 - t_ref) m1.
struct GyroRowConstants {
  bool body = true;
  double t0 = 0.0;
  Vec3 w0, h, m1r, m3r, U, S, m1, m3;
};

/// |phi|^2 up to which a constant twist's rows use so3::seriesCoefficients.
constexpr double kTwistSeriesLimit = so3::kSeriesLimit;

/// The EventLineTerms of one cluster's events without 3x3 products: the
/// cluster's constants are formed once (TwistRowConstants for a constant
/// twist; other motion models take R_k, and P_k unless it is tau I, from the
/// model). row() equals celcRow up to rounding. Keeps references to frame and
/// motion.
class ClusterRowTerms {
 public:
  ClusterRowTerms(const ClusterFrame& frame, const MotionModel& motion);
  EventLineTerms at(double t) const;
  /// The CELC row of bearing f at time t: a, and N's two nonzero rows.
  void row(double t, const Vec3& f, Vec3& a, Vec3& n0, Vec3& n1) const;
  /// The constant twist's constants; null for other motion models.
  const TwistRowConstants* twist() const { return twist_ ? &k_ : nullptr; }
  /// A gyro-integrated model's constants over its piece `index`
  /// (MotionModel::pieceIndex).
  GyroRowConstants gyroPiece(size_t index) const;
  const ClusterFrame& frame() const { return *frame_; }

 private:
  const ClusterFrame* frame_;
  const MotionModel* motion_;
  bool twist_;
  TwistRowConstants k_;
};

/// B_ref at time t (reference frame): l_ref(t) = B_ref v.
Mat3 transferMatrix(const ClusterFrame& frame, const MotionModel& motion, double t);
/// The same from P(t) (when the pose at t is at hand).
Mat3 transferMatrix(const ClusterFrame& frame, const Mat3& P);

/// The frames of a window's clusters, computed once per window: one for every
/// cluster usable with two events (usableClusters(obs, 2)), which holds every
/// cluster a method or the sign test uses.
class WindowFrames {
 public:
  WindowFrames(const WindowObservations& obs, const MotionModel& motion);
  /// The clusters with a frame: usableClusters(obs, 2), ascending.
  const std::vector<int>& clusters() const { return clusters_; }
  /// The frame of cluster c, one of clusters().
  const ClusterFrame& operator[](int c) const { return frames_[static_cast<size_t>(c)]; }
  /// How far cluster c's line moved, rotation removed [px] (lineMotionPx on
  /// kSignCentroidEvents events; NaN without lines): the weight of its sign vote.
  double lineMotionPx(int c) const { return line_motion_px_[static_cast<size_t>(c)]; }

 private:
  std::vector<int> clusters_;
  std::vector<ClusterFrame> frames_;  // by cluster index; set for clusters_
  std::vector<double> line_motion_px_;  // by cluster index; set for clusters_
};

}  // namespace celc::detail
