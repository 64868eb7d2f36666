#pragma once
// Internal: the linear constraint rows of CELC and CE3LC, and the frames of a
// window's clusters that every method and the sign test share. All vectors in
// the reference frame of the motion model unless said otherwise.
#include <vector>

#include "celc/geometry/motion_model.hpp"
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

 private:
  std::vector<int> clusters_;
  std::vector<ClusterFrame> frames_;  // by cluster index; set for clusters_
};

}  // namespace celc::detail
