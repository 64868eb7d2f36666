// Decoders of the ROS 1 message layouts in ros_messages.hpp.
#include "io/ros_messages.hpp"

#include <cmath>
#include <cstdio>

namespace celc::detail {

EventArrayView decodeEventArray(const unsigned char* data, std::size_t size) {
  RosCursor c(data, size);
  EventArrayView v;
  v.stamp = c.header();
  v.height = c.get<std::uint32_t>("height");
  v.width = c.get<std::uint32_t>("width");
  v.count = c.get<std::uint32_t>("events length");
  c.need(std::size_t(v.count) * kRosEventBytes, "events");
  v.events_offset = c.offset();
  v.events = c.here();
  return v;
}

ImuSample decodeImu(const unsigned char* data, std::size_t size) {
  RosCursor c(data, size);
  ImuSample s;
  s.t = c.header();
  c.skip(4 * 8 + 9 * 8, "orientation");
  const std::size_t gyro_at = c.offset();
  s.gyro = c.vec3("angular_velocity");
  c.skip(9 * 8, "angular_velocity_covariance");
  const std::size_t accel_at = c.offset();
  s.accel = c.vec3("linear_acceleration");
  c.skip(9 * 8, "linear_acceleration_covariance");
  auto check = [](const Vec3& v, double bound, std::size_t at, const char* what, const char* unit) {
    if (v.allFinite() && v.cwiseAbs().maxCoeff() <= bound) return;
    char m[160];
    std::snprintf(m, sizeof m, "%s (%.6g, %.6g, %.6g) %s: non-finite or beyond %g %s (not an IMU sample)", what,
                  v.x(), v.y(), v.z(), unit, bound, unit);
    throw RosDecodeError(at, m);
  };
  check(s.gyro, kMaxImuGyro, gyro_at, "angular_velocity", "rad/s");
  check(s.accel, kMaxImuAccel, accel_at, "linear_acceleration", "m/s^2");
  return s;
}

namespace {
PoseSample readPose(RosCursor& c, double t) {
  PoseSample p;
  p.t = t;
  const std::size_t at = c.offset();
  p.position = c.vec3("pose.position");
  const double x = c.get<double>("pose.orientation");
  const double y = c.get<double>("pose.orientation");
  const double z = c.get<double>("pose.orientation");
  const double w = c.get<double>("pose.orientation");
  const Eigen::Quaterniond q(w, x, y, z);
  const double n = q.norm();
  if (!(n > 1e-12) || !std::isfinite(n) || !p.position.allFinite())
    throw RosDecodeError(at, "pose with a zero or non-finite quaternion or position");
  p.orientation = q.normalized();
  return p;
}
}  // namespace

PoseSample decodePoseStamped(const unsigned char* data, std::size_t size) {
  RosCursor c(data, size);
  const double t = c.header();
  return readPose(c, t);
}

PoseSample decodeOdometry(const unsigned char* data, std::size_t size) {
  RosCursor c(data, size);
  const double t = c.header();
  const auto len = c.get<std::uint32_t>("child_frame_id");
  c.skip(len, "child_frame_id");
  return readPose(c, t);
}

RosCameraInfo decodeCameraInfo(const unsigned char* data, std::size_t size) {
  RosCursor c(data, size);
  RosCameraInfo info;
  c.header();
  info.height = c.get<std::uint32_t>("height");
  info.width = c.get<std::uint32_t>("width");
  info.distortion_model = c.string("distortion_model", 64);
  const auto n = c.get<std::uint32_t>("D length");
  c.need(std::size_t(n) * 8, "D");
  for (std::uint32_t i = 0; i < n; ++i) {
    const double d = c.get<double>("D");
    if (i < 16) info.D.push_back(d);
  }
  for (double& k : info.K) k = c.get<double>("K");
  return info;
}

}  // namespace celc::detail
