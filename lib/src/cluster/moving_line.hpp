#pragma once
// Internal: a cluster's moving line in the motion model's reference frame.
#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc::detail {

/// The moving line of a cluster in the reference frame of the motion model:
/// the plane normal n(t) = N1 + (t - t1) / (t3 - t1) (N3 - N1), N = R(t) m of
/// its fitted l1 (at t1) and l3 (at t3), each m scaled so that its image part
/// (m_x, m_y) has unit length; exact for a camera translating at constant
/// velocity (lines/line_fit.hpp, the moving model).
struct MovingLine {
  Vec3 n1, n3;
  double t1 = 0.0, t3 = 0.0;
  Vec3 at(double t) const { return n1 + (t - t1) / (t3 - t1) * (n3 - n1); }
  /// Distance of the reference-frame bearing g = R(t) f of an event at t
  /// [normalised units]: n.g = m.f, the point-line distance in the image of
  /// the camera at t (n's image part is about unit length there).
  double distance(double t, const Vec3& g) const { return std::abs(at(t).dot(g)); }
};

/// The cluster's moving line; false when it has no lines (or they are not
/// finite). `motion` null: no rotation.
bool movingLine(const ClusterObservation& cluster, const MotionModel* motion, MovingLine& line);

/// R(t), or the identity without a motion model.
Mat3 rotationAt(const MotionModel* motion, double t);

}  // namespace celc::detail
