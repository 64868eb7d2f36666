// The model-error budget of sigma_deg: gyroscope and calibration errors
// propagated to the direction.
#include "celc/solver/error_budget.hpp"

#include <cmath>

namespace celc {

namespace {

/// Rotation by `angle` [rad] about the unit axis `axis` (Rodrigues).
Mat3 axisRotation(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

}  // namespace

ErrorBudget::ErrorBudget(const WindowObservations& obs, const MotionModel& motion, const UncertaintyOptions& o) {
  const int n = o.max_events;
  const Mat3 I = Mat3::Identity();
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 e = Vec3::Unit(axis);
    if (o.gyro_bias_rad_s > 0.0)
      changed_.push_back(std::make_unique<DirectionTerms>(obs, motion.withRateTransform(I, o.gyro_bias_rad_s * e), n));
    if (o.gyro_scale > 0.0)
      changed_.push_back(std::make_unique<DirectionTerms>(
          obs, motion.withRateTransform(I + o.gyro_scale * e * e.transpose(), Vec3::Zero()), n));
    if (o.imu_rotation_deg > 0.0)
      changed_.push_back(std::make_unique<DirectionTerms>(
          obs, motion.withRateTransform(axisRotation(e, o.imu_rotation_deg * M_PI / 180.0), Vec3::Zero()), n));
  }
  if (obs.focal_px > 0.0 && o.principal_point_px > 0.0)
    for (int axis = 0; axis < 2; ++axis) {
      // A principal point off by +p px moves every normalised coordinate by -p / focal.
      BearingChange change;
      change.offset(axis) = -o.principal_point_px / obs.focal_px;
      changed_.push_back(std::make_unique<DirectionTerms>(obs, motion, n, &change));
    }
  if (o.focal_share > 0.0) {
    // A focal length (1 + s) times the one used scales the normalised coordinates by 1 / (1 + s).
    BearingChange change;
    change.scale = 1.0 / (1.0 + o.focal_share);
    changed_.push_back(std::make_unique<DirectionTerms>(obs, motion, n, &change));
  }
}

ErrorBudget::~ErrorBudget() = default;

double ErrorBudget::sigmaDeg(const DirectionTerms& base, const Vec3& direction) const {
  std::vector<const DirectionTerms*> changed;
  for (const auto& c : changed_) changed.push_back(c.get());
  double sum = 0.0;
  for (const Eigen::Vector2d& s : base.shifts(direction, changed)) {
    if (!s.allFinite()) return NAN;
    sum += s.squaredNorm();
  }
  return std::sqrt(sum) * 180.0 / M_PI;
}

}  // namespace celc
