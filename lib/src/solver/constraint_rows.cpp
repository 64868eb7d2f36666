// The row maths: cluster frames, transfer matrices, CELC rows.
#include "constraint_rows.hpp"

#include <cmath>

#include "celc/geometry/line_motion.hpp"
#include "sign_test.hpp"
#include "window_checks.hpp"

namespace celc {

ClusterFrame makeClusterFrame(const ClusterObservation& c, const MotionModel& motion) {
  ClusterFrame f;
  Mat3 R1, R3;
  motion.pose(c.l1.t, R1, f.Ps);
  motion.pose(c.l3.t, R3, f.Pe);
  f.m1 = R1 * c.l1.normal;
  f.m3 = R3 * c.l3.normal;
  return f;
}

namespace detail {

Mat3 transferMatrix(const ClusterFrame& frame, const Mat3& Pk) {
  const Vec3 u = (frame.Pe - Pk).transpose() * frame.m3;
  const Vec3 s = (frame.Ps - Pk).transpose() * frame.m1;
  return frame.m1 * u.transpose() - frame.m3 * s.transpose();
}

Mat3 transferMatrix(const ClusterFrame& frame, const MotionModel& motion, double t) {
  return transferMatrix(frame, motion.positionMatrix(t));
}

ConstraintRow celcRow(const ClusterFrame& frame, const MotionModel& motion, double t,
                      const Vec3& f) {
  Mat3 Rk, Pk;
  motion.pose(t, Rk, Pk);
  const Mat3 B_ref = transferMatrix(frame, Pk);
  ConstraintRow row;
  row.a = B_ref.transpose() * (Rk * f);
  row.N.topRows<2>() = Rk.transpose().topRows<2>() * B_ref;
  row.N.row(2).setZero();
  return row;
}

ClusterRowTerms::ClusterRowTerms(const ClusterFrame& frame, const MotionModel& motion)
    : frame_(&frame), motion_(&motion), twist_(motion.kind() == MotionModelKind::ConstantTwist) {
  k_.t_ref = motion.referenceTime();
  k_.m1 = frame.m1, k_.m3 = frame.m3;
  k_.u0 = frame.Pe.transpose() * frame.m3;
  k_.s0 = frame.Ps.transpose() * frame.m1;
  if (!twist_) return;
  const Vec3 w = motion.meanOmega(k_.t_ref, k_.t_ref);
  k_.w2 = w.squaredNorm();
  k_.wm1 = w.cross(k_.m1), k_.wm3 = w.cross(k_.m3);
  k_.wwm1 = w.cross(k_.wm1), k_.wwm3 = w.cross(k_.wm3);
}

EventLineTerms ClusterRowTerms::at(double t) const {
  EventLineTerms e;
  if (twist_) {
    const double tau = t - k_.t_ref, tau2 = tau * tau, x = k_.w2 * tau2;
    double A, B, C;
    so3::coefficients(x, A, B, C);
    const double ra = A * tau, rb = B * tau2, pc = C * tau2 * tau;
    e.g1 = k_.m1 - ra * k_.wm1 + rb * k_.wwm1;
    e.g3 = k_.m3 - ra * k_.wm3 + rb * k_.wwm3;
    e.u = k_.u0 - (tau * k_.m3 - rb * k_.wm3 + pc * k_.wwm3);
    e.s = k_.s0 - (tau * k_.m1 - rb * k_.wm1 + pc * k_.wwm1);
    return e;
  }
  const MotionModel::TransposedActions pa = motion_->transposedActions(t, k_.m1, k_.m3);
  e.g1 = pa.Rt_a, e.g3 = pa.Rt_b;
  e.u = k_.u0 - pa.Pt_b;
  e.s = k_.s0 - pa.Pt_a;
  return e;
}

GyroRowConstants ClusterRowTerms::gyroPiece(size_t index) const {
  const MotionModel::RotationPiece p = motion_->piece(index);
  GyroRowConstants g;
  g.body = motion_->velocityFrame() == VelocityFrame::Body;
  g.t0 = p.t0, g.w0 = p.w0, g.h = p.h;
  g.m1 = k_.m1, g.m3 = k_.m3;
  g.m1r = p.R0.transpose() * k_.m1, g.m3r = p.R0.transpose() * k_.m3;
  if (g.body) {
    g.U = k_.u0 - p.P0.transpose() * k_.m3;
    g.S = k_.s0 - p.P0.transpose() * k_.m1;
  } else {
    g.U = k_.u0 - (p.t0 - k_.t_ref) * k_.m3;
    g.S = k_.s0 - (p.t0 - k_.t_ref) * k_.m1;
  }
  return g;
}

void ClusterRowTerms::row(double t, const Vec3& f, Vec3& a, Vec3& n0, Vec3& n1) const {
  const EventLineTerms e = at(t);
  a = e.g1.dot(f) * e.u - e.g3.dot(f) * e.s;
  n0 = e.g1.x() * e.u - e.g3.x() * e.s;
  n1 = e.g1.y() * e.u - e.g3.y() * e.s;
}

WindowFrames::WindowFrames(const WindowObservations& obs, const MotionModel& motion)
    : clusters_(usableClusters(obs, 2)), frames_(obs.clusters.size()), line_motion_px_(obs.clusters.size(), NAN) {
  for (int c : clusters_) {
    frames_[static_cast<size_t>(c)] = makeClusterFrame(obs.clusters[c], motion);
    line_motion_px_[static_cast<size_t>(c)] =
        celc::lineMotionPx(obs.clusters[c], motion, obs.focal_px, kSignCentroidEvents);
  }
}

}  // namespace detail
}  // namespace celc
