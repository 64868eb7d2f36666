// The rotation-free motion of a cluster's line.
#include "celc/geometry/line_motion.hpp"

#include <algorithm>
#include <cmath>

namespace celc {

double lineMotionPx(const ClusterObservation& cluster, const MotionModel& motion, double focal_px,
                    std::size_t centroid_events) {
  if (!cluster.has_lines || cluster.size() == 0) return NAN;
  const Vec3 m1 = motion.rotate(cluster.l1.t, cluster.l1.normal);
  Vec3 m3 = motion.rotate(cluster.l3.t, cluster.l3.normal);
  if (m1.dot(m3) < 0.0) m3 = -m3;  // the sign of a normal is free: orient l3 as l1
  Vec3 centroid = Vec3::Zero();
  int n = 0;
  const std::size_t step = std::max<std::size_t>(1, cluster.size() / std::max<std::size_t>(1, centroid_events));
  for (std::size_t j = 0; j < cluster.size(); j += step) {
    const Vec3 g = motion.rotate(cluster.times[j], cluster.bearings[j]);
    if (!(g.z() > 1e-9)) continue;
    centroid += g / g.z();
    ++n;
  }
  if (n == 0) return NAN;
  centroid /= n;
  auto distance = [&](const Vec3& m) { return m.dot(centroid) / m.head<2>().norm(); };
  return focal_px * std::abs(distance(m1) - distance(m3));
}

}  // namespace celc
