// A cluster's moving line.
#include "moving_line.hpp"

#include <cmath>

namespace celc::detail {

Mat3 rotationAt(const MotionModel* motion, double t) {
  return motion ? motion->rotation(t) : Mat3::Identity();
}

bool movingLine(const ClusterObservation& cluster, const MotionModel* motion, MovingLine& line) {
  if (!cluster.has_lines || cluster.size() == 0 || !(cluster.l3.t > cluster.l1.t)) return false;
  line.t1 = cluster.l1.t;
  line.t3 = cluster.l3.t;
  auto imageNormal = [&](const Vec3& m, double t) -> Vec3 {
    return rotationAt(motion, t) * (m / std::hypot(m.x(), m.y()));
  };
  line.n1 = imageNormal(cluster.l1.normal, line.t1);
  line.n3 = imageNormal(cluster.l3.normal, line.t3);
  if (line.n3.dot(line.n1) < 0.0) line.n3 = -line.n3;
  return line.n1.allFinite() && line.n3.allFinite();
}

}  // namespace celc::detail
