#pragma once
/// \file celc_residual.hpp
/// The CELC event residual, shared by the solver's refinement and the
/// Cramér-Rao bound (eval/crlb.hpp): the distance of an event to the line that
/// l1 and l3 transfer to its time.
///
/// With the motion model's R(t) and p(t) = P(t) v (reference frame), a
/// cluster's lines l1 (at t_s) and l3 (at t_e) are the plane normals
/// m1 = R(t_s) l1 and m3 = R(t_e) l3 in the reference frame. At an event's time
/// t_k the plane through the camera centre and the 3D line has the normal
///   l = m1 (u.v) - m3 (s.v),  u = (P_e - P_k)^T m3,  s = (P_s - P_k)^T m1
/// (reference frame), and the event with bearing f = (x, y, 1) (camera at t_k)
/// lies at the distance
///   d = focal * (R_k f).l / |g|,  g = first two components of R_k^T l,
/// from the transferred line, in pixels when focal is the focal length in
/// pixels. d is linear in v up to the normalisation |g|: the linear solver's
/// row a_k with a_k.v = (R_k f).l.
#include <cmath>

#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"

namespace celc {

/// What a cluster contributes independently of its events: the reference-frame
/// plane normals of l1 and l3 and P at their times.
struct ClusterFrame {
  Vec3 m1, m3;   ///< R(t_s) l1, R(t_e) l3
  Mat3 Ps, Pe;   ///< P(t_s), P(t_e)
};
ClusterFrame makeClusterFrame(const ClusterObservation& cluster, const MotionModel& motion);

/// An event's constants in the residual.
struct EventTerm {
  Vec3 fp;                            ///< R_k f_k (reference frame)
  Eigen::Matrix<double, 2, 3> Rt01;   ///< first two rows of R_k^T
  Mat3 De, Ds;                        ///< P(t_e) - P(t_k), P(t_s) - P(t_k)
};
/// The event term of bearing f seen at the pose (Rk, Pk) (R(t_k), P(t_k)).
inline EventTerm makeEventTerm(const ClusterFrame& frame, const Mat3& Rk, const Mat3& Pk,
                               const Vec3& f) {
  return EventTerm{Rk * f, Rk.transpose().topRows<2>(), frame.Pe - Pk, frame.Ps - Pk};
}

/// d [px when focal is in px] for v and the lines m1, m3 (any norm), and its
/// gradients with respect to v, m1, m3 (any gradient pointer may be null).
/// NaN when the transferred line has no image direction (|g| = 0).
inline double eventDistance(const EventTerm& e, const Vec3& v, const Vec3& m1, const Vec3& m3,
                            double focal, Vec3* dv, Vec3* dm1, Vec3* dm3) {
  const Vec3 u = e.De.transpose() * m3, s = e.Ds.transpose() * m1;
  const double uv = u.dot(v), sv = s.dot(v);
  const Vec3 l = m1 * uv - m3 * sv;
  const Eigen::Vector2d g = e.Rt01 * l;
  const double gn = g.norm();
  if (!(gn > 1e-300)) return NAN;
  const double num = e.fp.dot(l);
  const double d = focal * num / gn;
  if (dv || dm1 || dm3) {
    // dd/dl (as a column vector).
    const Vec3 dl = focal * (e.fp / gn - num * (e.Rt01.transpose() * g) / (gn * gn * gn));
    // dl/dv = m1 u^T - m3 s^T, dl/dm1 = uv I - m3 (Ds v)^T, dl/dm3 = m1 (De v)^T - sv I.
    const double m1dl = m1.dot(dl), m3dl = m3.dot(dl);
    if (dv) *dv = u * m1dl - s * m3dl;
    if (dm1) *dm1 = uv * dl - (e.Ds * v) * m3dl;
    if (dm3) *dm3 = (e.De * v) * m1dl - sv * dl;
  }
  return d;
}

}  // namespace celc
