#pragma once
// Private: the serialised layout of the few ROS 1 message types celc reads
// from a bag (little-endian, fields in declaration order, no padding; a
// variable array or string is a uint32 count then its elements; `time` is
// uint32 sec, uint32 nsec):
//   std_msgs/Header:           uint32 seq, time stamp, string frame_id
//   dvs_msgs/EventArray:       Header, uint32 height, uint32 width, Event[] events
//   dvs_msgs/Event (13 bytes): uint16 x, uint16 y, time ts, bool polarity
//   sensor_msgs/Imu:           Header, Quaternion orientation, float64[9], Vector3 angular_velocity
//                              [rad/s], float64[9], Vector3 linear_acceleration [m/s^2], float64[9]
//   geometry_msgs/PoseStamped: Header, Point position [m], Quaternion orientation (x y z w)
//   nav_msgs/Odometry:         Header, string child_frame_id, Pose, float64[36], Twist, float64[36]
//   sensor_msgs/CameraInfo:    Header, uint32 height, uint32 width, string distortion_model,
//                              float64[] D, float64[9] K, float64[9] R, float64[12] P, ...
// Every decoder checks each length against the bytes left and throws
// RosDecodeError with the offset inside the message.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "celc/core/types.hpp"

namespace celc::detail {

namespace ros_type {
inline constexpr const char* kEventArray = "dvs_msgs/EventArray";
inline constexpr const char* kImu = "sensor_msgs/Imu";
inline constexpr const char* kPoseStamped = "geometry_msgs/PoseStamped";
inline constexpr const char* kOdometry = "nav_msgs/Odometry";
inline constexpr const char* kCameraInfo = "sensor_msgs/CameraInfo";
}  // namespace ros_type

/// A message type celc decodes: its name, the MD5 sum of its definition and
/// the definition's fields (the layout the decoders below read).
struct RosTypeSum {
  const char* type;
  const char* md5sum;
  const char* fields;
};
/// The MD5 sums of the decoded types, by the ROS 1 rule: the MD5 of the
/// definition text with comments and blank lines dropped, constants first,
/// then one line "type name" per field, where a field of another message type
/// (arrays too) is written as that type's own MD5 sum; lines joined by '\n'
/// without a final one. The nested sums: std_msgs/Header
/// 2176decaecbce78abc3b96ef049fabed, dvs_msgs/Event
/// 40d339b261445b8ce9a6fef01267cd5d. A connection recorded with another sum
/// carries another layout under the same name, which these decoders would
/// misread: the reader refuses it.
inline constexpr RosTypeSum kRosTypeSums[] = {
    {ros_type::kEventArray, "5e8beee5a6c107e504c2e78903c224b8",
     "Header header, uint32 height, uint32 width, Event[] events (uint16 x, uint16 y, time ts, bool polarity)"},
    {ros_type::kImu, "6a62c6daae103f4ff57a132d6f95cec2",
     "Header header, Quaternion orientation, float64[9] orientation_covariance, Vector3 angular_velocity, "
     "float64[9] angular_velocity_covariance, Vector3 linear_acceleration, float64[9] linear_acceleration_covariance"},
    {ros_type::kPoseStamped, "d3812c3cbc69362b77dc0b19b345f8f5", "Header header, Pose pose"},
    {ros_type::kOdometry, "cd5e73d190d741a2f92e81eda573aca7",
     "Header header, string child_frame_id, PoseWithCovariance pose, TwistWithCovariance twist"},
    {ros_type::kCameraInfo, "c9a58c1b0b154e0e6da7578cb991d214",
     "Header header, uint32 height, uint32 width, string distortion_model, float64[] D, float64[9] K, "
     "float64[9] R, float64[12] P, uint32 binning_x, uint32 binning_y, RegionOfInterest roi"},
};
/// The entry of kRosTypeSums for `type`; nullptr for a type celc does not decode.
inline const RosTypeSum* rosTypeSum(const std::string& type) {
  for (const RosTypeSum& t : kRosTypeSums)
    if (type == t.type) return &t;
  return nullptr;
}

/// A message shorter than its layout, or a value out of range; `offset` is the
/// byte inside the message.
class RosDecodeError : public std::runtime_error {
 public:
  RosDecodeError(std::size_t at, const std::string& what) : std::runtime_error(what), offset(at) {}
  std::size_t offset;
};

/// ROS time -> seconds. Exact (correctly rounded from the integer nanoseconds)
/// below 2^53 ns, so that a time written as whole microseconds reads as the same
/// double as its decimal text; nsec >= 1e9 is an error (offset `at`).
inline double rosTimeSeconds(std::uint32_t sec, std::uint32_t nsec, std::size_t at) {
  if (nsec >= 1000000000u) throw RosDecodeError(at, "time nsec " + std::to_string(nsec) + " >= 1e9");
  const std::uint64_t ns = std::uint64_t(sec) * 1000000000u + nsec;
  if (ns < (std::uint64_t(1) << 53)) return double(ns) / 1e9;
  return double(sec) + double(nsec) / 1e9;
}

/// Bounds-checked reading through one serialised message.
class RosCursor {
 public:
  RosCursor(const unsigned char* data, std::size_t size) : p_(data), n_(size) {}
  std::size_t offset() const { return at_; }
  std::size_t left() const { return n_ - at_; }
  const unsigned char* here() const { return p_ + at_; }
  void need(std::size_t k, const char* what) const {
    if (k > n_ - at_)
      throw RosDecodeError(at_, std::string("message ends inside ") + what + " (needs " + std::to_string(k) +
                                    " bytes, " + std::to_string(n_ - at_) + " left)");
  }
  template <typename T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, p_ + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  void skip(std::size_t k, const char* what) {
    need(k, what);
    at_ += k;
  }
  double time(const char* what) {
    const std::size_t at = at_;
    const auto sec = get<std::uint32_t>(what);
    const auto nsec = get<std::uint32_t>(what);
    return rosTimeSeconds(sec, nsec, at);
  }
  std::string string(const char* what, std::size_t max = 4096) {
    const auto len = get<std::uint32_t>(what);
    need(len, what);
    const std::size_t keep = std::min<std::size_t>(len, max);
    std::string s(reinterpret_cast<const char*>(p_ + at_), keep);
    at_ += len;
    return s;
  }
  /// Skips a std_msgs/Header; returns its stamp [s].
  double header() {
    skip(4, "header.seq");
    const double t = time("header.stamp");
    const auto len = get<std::uint32_t>("header.frame_id");
    skip(len, "header.frame_id");
    return t;
  }
  Vec3 vec3(const char* what) {
    need(24, what);
    const double x = get<double>(what);  // one statement each: argument order is unspecified
    const double y = get<double>(what);
    const double z = get<double>(what);
    return Vec3(x, y, z);
  }

 private:
  const unsigned char* p_;
  std::size_t n_;
  std::size_t at_ = 0;
};

/// The fixed part of a dvs_msgs/EventArray and where its events are.
struct EventArrayView {
  double stamp = 0.0;  ///< header stamp [s]
  std::uint32_t width = 0, height = 0;
  std::uint32_t count = 0;
  const unsigned char* events = nullptr;  ///< count x kRosEventBytes
  std::size_t events_offset = 0;          ///< byte of the first event inside the message
};
inline constexpr std::size_t kRosEventBytes = 13;
EventArrayView decodeEventArray(const unsigned char* data, std::size_t size);

/// One dvs_msgs/Event of an EventArray: x, y [px], ts as the raw sec / nsec, polarity.
struct RosEvent {
  std::uint16_t x, y;
  std::uint32_t sec, nsec;
  bool on;
};
inline RosEvent loadRosEvent(const unsigned char* p) {
  RosEvent e;
  std::memcpy(&e.x, p, 2);
  std::memcpy(&e.y, p + 2, 2);
  std::memcpy(&e.sec, p + 4, 4);
  std::memcpy(&e.nsec, p + 8, 4);
  e.on = p[12] != 0;
  return e;
}

/// Largest |component| of a decoded IMU sample: a gyro rate beyond 1000 rad/s
/// or an acceleration beyond 10^4 m/s^2 (about 1000 g) is no IMU's reading but
/// another message or damaged bytes.
inline constexpr double kMaxImuGyro = 1e3;    ///< [rad/s]
inline constexpr double kMaxImuAccel = 1e4;   ///< [m/s^2]
/// sensor_msgs/Imu: time = header stamp; gyro = angular_velocity, accel =
/// linear_acceleration. A non-finite value or one beyond kMaxImuGyro /
/// kMaxImuAccel is a RosDecodeError at the vector's offset.
ImuSample decodeImu(const unsigned char* data, std::size_t size);
/// geometry_msgs/PoseStamped or nav_msgs/Odometry (its pose.pose): T_world_body at the header stamp;
/// the quaternion is normalised (a zero quaternion is an error).
PoseSample decodePoseStamped(const unsigned char* data, std::size_t size);
PoseSample decodeOdometry(const unsigned char* data, std::size_t size);

/// sensor_msgs/CameraInfo, the parts celc uses.
struct RosCameraInfo {
  std::uint32_t width = 0, height = 0;
  std::string distortion_model;  ///< "plumb_bob", "rational_polynomial", "equidistant", ...
  std::vector<double> D;         ///< at most 16 kept
  double K[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
};
RosCameraInfo decodeCameraInfo(const unsigned char* data, std::size_t size);

}  // namespace celc::detail
