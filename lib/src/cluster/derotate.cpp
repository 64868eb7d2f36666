// A window's events turned back by the gyro's rotation (derotate.hpp).
#include "celc/cluster/derotate.hpp"

#include <cmath>
#include <limits>

namespace celc {

namespace {
// Events this close in time share one rotation [s] (3 rad/s: 0.05 px at f = 320 px).
constexpr double kRotationStep = 5e-5;
// cos(60 deg): a turned bearing farther from the optical axis is not projected.
constexpr double kMinAxisCosine = 0.5;
}  // namespace

std::vector<Event> derotateEvents(const std::vector<Event>& events, const BearingFunction& bearing,
                                  const CameraModel& camera, const MotionModel& motion, double t_ref) {
  std::vector<Event> out(events);
  const Mat3 ref_from_window = motion.rotation(t_ref).transpose();
  Mat3 turn = Mat3::Identity();  // R(t_ref)^T R(t) at turn_time
  double turn_time = std::numeric_limits<double>::quiet_NaN();
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  for (Event& e : out) {
    if (!(std::abs(e.t - turn_time) <= kRotationStep)) {
      if (!std::isfinite(e.t)) {
        e.x = e.y = kNaN;
        continue;
      }
      turn = ref_from_window * motion.rotation(e.t);
      turn_time = e.t;
    }
    const Vec3 g = turn * bearing(Vec2(e.x, e.y));
    if (!g.allFinite() || !(g.z() >= kMinAxisCosine * g.norm())) {
      e.x = e.y = kNaN;
      continue;
    }
    e.x = static_cast<float>(camera.fx * g.x() / g.z() + kDerotatedCentrePx);
    e.y = static_cast<float>(camera.fy * g.y() / g.z() + kDerotatedCentrePx);
  }
  return out;
}

}  // namespace celc
