// The row maths: cluster frames, transfer matrices, CELC rows.
#include "constraint_rows.hpp"

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

WindowFrames::WindowFrames(const WindowObservations& obs, const MotionModel& motion)
    : clusters_(usableClusters(obs, 2)), frames_(obs.clusters.size()) {
  for (int c : clusters_) frames_[static_cast<size_t>(c)] = makeClusterFrame(obs.clusters[c], motion);
}

}  // namespace detail
}  // namespace celc
