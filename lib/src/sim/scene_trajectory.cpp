#include "celc/sim/scene_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "celc/geometry/so3.hpp"

namespace celc {

TrajectoryKind parseTrajectoryKind(const std::string& name) {
  if (name == "constant_twist") return TrajectoryKind::ConstantTwist;
  if (name == "piecewise") return TrajectoryKind::Piecewise;
  if (name == "sinusoid") return TrajectoryKind::Sinusoid;
  if (name == "constant_acceleration") return TrajectoryKind::ConstantAcceleration;
  throw std::invalid_argument("unknown trajectory type '" + name +
                              "' (expected constant_twist, piecewise, sinusoid or constant_acceleration)");
}

std::string toString(TrajectoryKind kind) {
  switch (kind) {
    case TrajectoryKind::ConstantTwist:
      return "constant_twist";
    case TrajectoryKind::Piecewise:
      return "piecewise";
    case TrajectoryKind::Sinusoid:
      return "sinusoid";
    case TrajectoryKind::ConstantAcceleration:
      return "constant_acceleration";
  }
  return "constant_twist";
}

RigidPose twistExp(const Vec3& v, const Vec3& w, double tau) {
  const Vec3 phi = w * tau;
  return {so3::exp(phi), so3::leftJacobian(phi) * v * tau};
}

Trajectory::Trajectory(const TrajectorySpec& spec, double horizon) : spec_(spec) {
  const std::string err = spec.validate();
  if (!err.empty()) throw std::invalid_argument("trajectory: " + err);
  if (spec.kind == TrajectoryKind::Piecewise) {
    double t = 0.0;
    RigidPose T = spec.initial;
    for (const TwistSegment& s : spec.segments) {
      seg_start_.push_back(t);
      seg_pose_.push_back(T);
      T = T * twistExp(s.v, s.w, s.duration);
      t += s.duration;
    }
  } else if (spec.kind == TrajectoryKind::Sinusoid) {
    // At most ~200k knots (19 MB): 0.1 ms spacing up to 20 s, coarser beyond.
    knot_dt_ = std::max(1e-4, std::max(horizon, 0.0) / 2e5);
    const size_t n = static_cast<size_t>(std::ceil(std::max(horizon, 0.0) / knot_dt_)) + 2;
    knots_.resize(n);
    knots_[0] = spec.initial;
    for (size_t k = 1; k < n; ++k) {
      const double tm = (k - 0.5) * knot_dt_;
      knots_[k] = knots_[k - 1] * twistExp(linearVelocity(tm), angularVelocity(tm), knot_dt_);
    }
  }
}

int Trajectory::segmentAt(double t) const {
  const auto it = std::upper_bound(seg_start_.begin(), seg_start_.end(), t);
  return std::max(0, static_cast<int>(it - seg_start_.begin()) - 1);
}

RigidPose Trajectory::pose(double t) const {
  switch (spec_.kind) {
    case TrajectoryKind::ConstantTwist:
      return spec_.initial * twistExp(spec_.v, spec_.w, t);
    case TrajectoryKind::Piecewise: {
      const int i = segmentAt(t);
      const TwistSegment& s = spec_.segments[i];
      return seg_pose_[i] * twistExp(s.v, s.w, t - seg_start_[i]);
    }
    case TrajectoryKind::Sinusoid: {
      if (t <= 0.0) return spec_.initial * twistExp(spec_.v, spec_.w, t);
      const size_t last = knots_.size() - 1;
      const size_t k = std::min(static_cast<size_t>(t / knot_dt_), last);
      const double t_k = k * knot_dt_;
      const double tau = t - t_k;
      if (k == last) return knots_[k] * twistExp(linearVelocity(t_k), angularVelocity(t_k), tau);
      const double tm = t_k + 0.5 * tau;
      return knots_[k] * twistExp(linearVelocity(tm), angularVelocity(tm), tau);
    }
    case TrajectoryKind::ConstantAcceleration: {
      const RigidPose& T0 = spec_.initial;
      return {T0.R * so3::exp(spec_.w * t), T0.p + T0.R * (spec_.v * t + 0.5 * t * t * spec_.acceleration)};
    }
  }
  return spec_.initial;
}

Vec3 Trajectory::linearVelocity(double t) const {
  switch (spec_.kind) {
    case TrajectoryKind::ConstantTwist:
      return spec_.v;
    case TrajectoryKind::Piecewise:
      return spec_.segments[segmentAt(t)].v;
    case TrajectoryKind::Sinusoid:
      return spec_.v + spec_.amplitude_v * std::sin(2.0 * M_PI * spec_.frequency * t);
    case TrajectoryKind::ConstantAcceleration:
      return so3::exp(spec_.w * t).transpose() * (spec_.v + spec_.acceleration * t);
  }
  return spec_.v;
}

Vec3 Trajectory::angularVelocity(double t) const {
  switch (spec_.kind) {
    case TrajectoryKind::ConstantTwist:
      return spec_.w;
    case TrajectoryKind::Piecewise:
      return spec_.segments[segmentAt(t)].w;
    case TrajectoryKind::Sinusoid:
      return spec_.w + spec_.amplitude_w * std::sin(2.0 * M_PI * spec_.frequency * t);
    case TrajectoryKind::ConstantAcceleration:
      return spec_.w;
  }
  return spec_.w;
}

double Trajectory::nextBreak(double t) const {
  const auto it = std::upper_bound(seg_start_.begin(), seg_start_.end(), t);
  return it == seg_start_.end() ? std::numeric_limits<double>::infinity() : *it;
}

double Trajectory::smoothTime() const {
  if (spec_.kind == TrajectoryKind::Sinusoid) return 0.01 / spec_.frequency;
  if (spec_.kind == TrajectoryKind::ConstantAcceleration && spec_.acceleration.norm() > 0.0)
    return 0.01 * std::max(spec_.v.norm(), 0.05) / spec_.acceleration.norm();
  return std::numeric_limits<double>::infinity();
}

/// Constant acceleration: d/dt of exp(w^ t)^T (v + a t) is
/// exp(w^ t)^T a - w x v(t).
Vec3 Trajectory::linearVelocityRate(double t) const {
  if (spec_.kind == TrajectoryKind::ConstantAcceleration)
    return so3::exp(spec_.w * t).transpose() * spec_.acceleration - spec_.w.cross(linearVelocity(t));
  if (spec_.kind != TrajectoryKind::Sinusoid) return Vec3::Zero();
  const double om = 2.0 * M_PI * spec_.frequency;
  return spec_.amplitude_v * om * std::cos(om * t);
}

}  // namespace celc
