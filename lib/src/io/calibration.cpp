#include "celc/io/calibration.hpp"


#include "io/aedat_readers.hpp"


#include <Eigen/LU>
#include <array>
#include <cmath>

#include "celc/core/yaml.hpp"
#include "celc/geometry/undistort.hpp"
#include "io/text_parse.hpp"

namespace celc {
namespace {

bool isRotation(const Mat3& R) {
  return (R.transpose() * R - Mat3::Identity()).norm() <= 1e-4 && R.determinant() > 0.0;
}

/// A row-major matrix as a list of numbers.
template <int Rows, int Cols>
void matrixField(FieldVisitor& v, const FieldInfo& info, Eigen::Matrix<double, Rows, Cols>& m) {
  const Eigen::Matrix<double, Cols, Rows> t = m.transpose();  // column-major storage = row-major m
  std::vector<double> flat(t.data(), t.data() + Rows * Cols);
  v.field(info, flat, {std::size_t(Rows * Cols)});
  m = Eigen::Map<const Eigen::Matrix<double, Rows, Cols, Eigen::RowMajor>>(flat.data());
}

void describeCalibration(FieldVisitor& v, Calibration& c) {
  v.require("camera");
  v.section({"camera", "", "intrinsics"}, [&](FieldVisitor& s) {
    for (const char* k : {"width", "height", "fx", "fy", "cx", "cy"}) s.require(k);
    describe(s, c.camera);
    // bounded before anything is sized from it (the undistortion table)
    if (c.camera.width > kMaxSensorSide)
      s.fail("width", "sensor width " + std::to_string(c.camera.width) + " exceeds " + std::to_string(kMaxSensorSide));
    if (c.camera.height > kMaxSensorSide)
      s.fail("height", "sensor height " + std::to_string(c.camera.height) + " exceeds " + std::to_string(kMaxSensorSide));
    const auto& k = c.camera.coeffs;
    if (c.camera.distortion == DistortionModel::None && (k[0] != 0 || k[1] != 0 || k[2] != 0 || k[3] != 0 || k[4] != 0))
      s.fail("distortion", "non-zero coefficients with distortion_model none");
    if (c.camera.distortion == DistortionModel::Equidistant && k[4] != 0.0)
      s.fail("distortion", "expected 4 numbers for equidistant");
    failOnFirstProblem(s, c.camera.validate());
  });
  c.has_imu = v.has("imu");
  v.section({"imu", "", "the IMU relative to the camera"}, [&](FieldVisitor& s) {
    if (s.reading() && s.has("R_cam_imu") && s.has("T_cam_imu"))
      s.fail("", "give either 'imu.R_cam_imu' or 'imu.T_cam_imu', not both");
    if (!s.reading() || !s.has("T_cam_imu")) {
      matrixField(s, {"R_cam_imu", "-", "rotation IMU -> camera, row-major 3x3"}, c.R_cam_imu);
    } else {
      Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
      matrixField(s, {"T_cam_imu", "m", "IMU pose in the camera frame, row-major 4x4 (rotation used)"}, T);
      c.R_cam_imu = T.topLeftCorner<3, 3>();
    }
    if (!isRotation(c.R_cam_imu))
      s.fail(s.has("T_cam_imu") ? "T_cam_imu" : "R_cam_imu", "not a rotation matrix (R^T R != I or det < 0)");
    s.field({"time_offset", "s", "t_cam = t_imu + time_offset"}, c.time_offset);
  });
  c.has_body = v.has("body");
  v.section({"body", "", "the camera relative to the body of the pose file"}, [&](FieldVisitor& s) {
    matrixField(s, {"T_body_cam", "m", "camera pose in the body frame, row-major 4x4"}, c.T_body_cam);
    if (!isRotation(c.T_body_cam.topLeftCorner<3, 3>()))
      s.fail("T_body_cam", "not a rotation matrix (R^T R != I or det < 0)");
    if ((c.T_body_cam.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
      s.fail("T_body_cam", "last row must be 0 0 0 1");
  });
}

}  // namespace

Calibration loadCalibrationYaml(const std::string& path) {
  Calibration c;
  c.camera.distortion = DistortionModel::None;
  try {
    readYamlFile(path, [&](FieldVisitor& v) { describeCalibration(v, c); });
  } catch (const ConfigError& e) {
    // yaml-cpp's syntax messages quote the offending byte raw: one printable line
    const std::string m = e.what();
    const std::string clean = detail::printable(m, 600);
    if (clean == m) throw;
    throw ConfigError(clean);
  }
  return c;
}

static_assert(kMaxReaderSensorSide == kMaxSensorSide, "the readers and the undistortion table share one bound");

Calibration loadCalibTxt(const std::string& path, int width, int height) {
  detail::LineReader lr(path);
  std::string_view line;
  Calibration c;
  while (lr.next(line)) {
    if (detail::isBlank(line) || line.find('#') == line.find_first_not_of(" \t")) continue;
    std::string_view f[10];
    const std::size_t n = detail::splitFields(line, f, 9);
    if (n != 9 && n != 4 && n != 8)
      lr.fail("expected 9 values 'fx fy cx cy k1 k2 p1 p2 k3' (or 4, or 8), found " +
              (n > 9 ? std::string("more than 9") : std::to_string(n)));
    double v[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < n; ++i)
      if (!detail::parseDouble(f[i], v[i]) || !std::isfinite(v[i]))
        lr.fail("non-numeric value '" + std::string(f[i].substr(0, 40)) + "' in column " + std::to_string(i + 1));
    CameraModel& m = c.camera;
    m.width = width;
    m.height = height;
    m.fx = v[0], m.fy = v[1], m.cx = v[2], m.cy = v[3];
    m.coeffs = {v[4], v[5], v[6], v[7], v[8]};
    bool any = false;
    for (double k : m.coeffs) any |= k != 0.0;
    m.distortion = any ? DistortionModel::RadTan : DistortionModel::None;
    const std::string err = m.validate();
    if (!err.empty()) lr.fail(err);
    return c;
  }
  throw IoError(path + ": no calibration line (expected 'fx fy cx cy k1 k2 p1 p2 k3')");
}

Calibration loadCalibration(const std::string& path, int width, int height) {
  // A ROS bag: the camera of its sensor_msgs/CameraInfo topic (no IMU or body section).
  if (isContainerFile(path) && detectFormat(path) == Format::RosBag) {
    Calibration c;
    if (!detail::bagCameraModel(path, c.camera))
      throw IoError(path + ": no sensor_msgs/CameraInfo topic: give the calibration (--calib FILE)");
    return c;
  }
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".yaml" || ext == ".yml") return loadCalibrationYaml(path);
  return loadCalibTxt(path, width, height);
}

}  // namespace celc
