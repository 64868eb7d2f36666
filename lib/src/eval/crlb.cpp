#include "celc/eval/crlb.hpp"

#include <cmath>
#include <limits>

#include "celc/solver/direction_information.hpp"

namespace celc {

CrlbResult velocityDirectionCrlb(const WindowObservations& truth, const MotionModel& motion,
                                 const Vec3& direction, double sigma_px) {
  CrlbResult out;
  if (!direction.allFinite() || !(direction.norm() > 0.0) || !(sigma_px >= 0.0) ||
      !std::isfinite(sigma_px) || !(truth.focal_px > 0.0)) {
    out.message = "invalid direction, sigma or focal length";
    return out;
  }
  // The information at the true parameters (solver/direction_information.hpp).
  const DirectionInformation info = directionInformation(truth, motion, direction);
  out.events = info.events;
  out.lines = info.lines;
  if (!info.ok) {
    out.message = info.message;
    return out;
  }
  out.ok = true;
  if (sigma_px == 0.0) return out;  // noise-free: zero bound
  const DirectionCovariance c = directionCovariance(info.schur, sigma_px);
  out.covariance = c.covariance;
  out.rms_rad = c.rms_rad;
  if (!c.observable) out.message = "direction not observable (singular Fisher information)";
  return out;
}

}  // namespace celc
