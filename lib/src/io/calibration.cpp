#include "celc/io/calibration.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <set>

#include "io/text_parse.hpp"

namespace celc::io {
namespace {

std::string where(const std::string& path, const YAML::Node& n) {
  const auto m = n.Mark();
  if (m.line >= 0) return path + ": line " + std::to_string(m.line + 1);
  return path;
}

[[noreturn]] void failKey(const std::string& path, const YAML::Node& n, const std::string& key,
                          const std::string& what) {
  throw IoError(where(path, n) + ": key '" + key + "': " + what);
}

double getDouble(const std::string& path, const YAML::Node& n, const std::string& key) {
  if (!n.IsScalar()) failKey(path, n, key, "expected a number");
  double v;
  const std::string s = n.Scalar();
  if (!detail::parseDouble(s, v) || !std::isfinite(v))
    failKey(path, n, key, "expected a finite number, found '" + s.substr(0, 40) + "'");
  return v;
}

int getInt(const std::string& path, const YAML::Node& n, const std::string& key) {
  if (!n.IsScalar()) failKey(path, n, key, "expected an integer");
  long long v;
  const std::string s = n.Scalar();
  if (!detail::parseInt(s, v) || v < 1 || v > 65535)
    failKey(path, n, key, "expected an integer in [1, 65535], found '" + s.substr(0, 40) + "'");
  return int(v);
}

std::vector<double> getList(const std::string& path, const YAML::Node& n, const std::string& key,
                            std::initializer_list<std::size_t> sizes) {
  if (!n.IsSequence()) failKey(path, n, key, "expected a list of numbers");
  std::vector<double> v;
  for (std::size_t i = 0; i < n.size(); ++i) v.push_back(getDouble(path, n[i], key + "[" + std::to_string(i) + "]"));
  bool ok = false;
  std::string expect;
  for (std::size_t s : sizes) {
    ok |= v.size() == s;
    expect += (expect.empty() ? "" : " or ") + std::to_string(s);
  }
  if (!ok) failKey(path, n, key, "expected " + expect + " numbers, found " + std::to_string(v.size()));
  return v;
}

void checkKeys(const std::string& path, const YAML::Node& map, const std::string& section,
               const std::set<std::string>& allowed) {
  if (!map.IsMap()) throw IoError(where(path, map) + ": section '" + section + "' must be a mapping");
  for (auto it = map.begin(); it != map.end(); ++it) {
    const std::string k = it->first.as<std::string>();
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw IoError(where(path, it->first) + ": unknown key '" + (section.empty() ? "" : section + ".") + k +
                    "' (expected one of: " + list + ")");
    }
  }
}

Mat3 checkRotation(const std::string& path, const YAML::Node& n, const std::string& key, const Mat3& R) {
  if ((R.transpose() * R - Mat3::Identity()).norm() > 1e-4 || R.determinant() < 0.0)
    failKey(path, n, key, "not a rotation matrix (R^T R != I or det < 0)");
  return R;
}

}  // namespace

Calibration loadCalibrationYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw IoError(path + ": cannot open");
  } catch (const YAML::Exception& e) {
    throw IoError(path + ": line " + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  if (!root.IsMap()) throw IoError(path + ": expected a mapping with 'camera', 'imu', 'body'");
  Calibration c;
  checkKeys(path, root, "", {"camera", "imu", "body"});
  const YAML::Node cam = root["camera"];
  if (!cam) throw IoError(path + ": missing section 'camera'");
  checkKeys(path, cam, "camera", {"width", "height", "fx", "fy", "cx", "cy", "distortion_model", "distortion"});
  CameraModel& m = c.camera;
  for (const char* k : {"width", "height", "fx", "fy", "cx", "cy"})
    if (!cam[k]) throw IoError(where(path, cam) + ": missing key 'camera." + std::string(k) + "'");
  m.width = getInt(path, cam["width"], "camera.width");
  m.height = getInt(path, cam["height"], "camera.height");
  m.fx = getDouble(path, cam["fx"], "camera.fx");
  m.fy = getDouble(path, cam["fy"], "camera.fy");
  m.cx = getDouble(path, cam["cx"], "camera.cx");
  m.cy = getDouble(path, cam["cy"], "camera.cy");
  m.distortion = DistortionModel::None;
  if (cam["distortion_model"]) {
    const YAML::Node dm = cam["distortion_model"];
    if (!dm.IsScalar()) failKey(path, dm, "camera.distortion_model", "expected none | radtan | equidistant");
    try {
      m.distortion = parseDistortionModel(dm.Scalar());
    } catch (const std::exception& e) {
      failKey(path, dm, "camera.distortion_model", e.what());
    }
  }
  m.coeffs = {0, 0, 0, 0, 0};
  if (cam["distortion"]) {
    const YAML::Node d = cam["distortion"];
    std::vector<double> v;
    if (m.distortion == DistortionModel::RadTan) v = getList(path, d, "camera.distortion", {4, 5});
    else if (m.distortion == DistortionModel::Equidistant) v = getList(path, d, "camera.distortion", {4});
    else {
      v = getList(path, d, "camera.distortion", {0, 4, 5});
      for (double x : v)
        if (x != 0.0) failKey(path, d, "camera.distortion", "non-zero coefficients with distortion_model none");
    }
    for (std::size_t i = 0; i < v.size(); ++i) m.coeffs[i] = v[i];
  }
  const std::string err = m.validate();
  if (!err.empty()) throw IoError(where(path, cam) + ": section 'camera': " + err);

  if (const YAML::Node imu = root["imu"]) {
    c.has_imu = true;
    checkKeys(path, imu, "imu", {"R_cam_imu", "T_cam_imu", "time_offset"});
    if (imu["R_cam_imu"] && imu["T_cam_imu"])
      throw IoError(where(path, imu) + ": give either 'imu.R_cam_imu' or 'imu.T_cam_imu', not both");
    if (imu["R_cam_imu"]) {
      auto v = getList(path, imu["R_cam_imu"], "imu.R_cam_imu", {9});
      Mat3 R;
      for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = v[std::size_t(i)];
      c.R_cam_imu = checkRotation(path, imu["R_cam_imu"], "imu.R_cam_imu", R);
    }
    if (imu["T_cam_imu"]) {
      auto v = getList(path, imu["T_cam_imu"], "imu.T_cam_imu", {16});
      Mat3 R;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R(i, j) = v[std::size_t(4 * i + j)];
      c.R_cam_imu = checkRotation(path, imu["T_cam_imu"], "imu.T_cam_imu", R);
    }
    if (imu["time_offset"]) c.time_offset = getDouble(path, imu["time_offset"], "imu.time_offset");
  }
  if (const YAML::Node body = root["body"]) {
    c.has_body = true;
    checkKeys(path, body, "body", {"T_body_cam"});
    if (body["T_body_cam"]) {
      auto v = getList(path, body["T_body_cam"], "body.T_body_cam", {16});
      for (int i = 0; i < 16; ++i) c.T_body_cam(i / 4, i % 4) = v[std::size_t(i)];
      checkRotation(path, body["T_body_cam"], "body.T_body_cam", c.T_body_cam.topLeftCorner<3, 3>());
      if ((c.T_body_cam.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
        failKey(path, body["T_body_cam"], "body.T_body_cam", "last row must be 0 0 0 1");
    }
  }
  return c;
}

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
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".yaml" || ext == ".yml") return loadCalibrationYaml(path);
  return loadCalibTxt(path, width, height);
}

}  // namespace celc::io
