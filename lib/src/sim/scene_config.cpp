// SCENE.yaml reader for `celc synth` (schema in docs/synth.md and config/scenes/).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "celc/geometry/so3.hpp"
#include "celc/sim/render_sequence.hpp"

namespace celc::sim {

namespace {

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& msg) const {
    const int line = at.IsDefined() ? at.Mark().line : -1;
    throw std::invalid_argument(file_ + (line >= 0 ? ":" + std::to_string(line + 1) : "") + ": " +
                                msg);
  }

  /// Every key of `map` must be in `allowed`.
  void keys(const YAML::Node& map, const std::string& path,
            const std::vector<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, "key '" + path + "' must be a mapping");
    for (auto it = map.begin(); it != map.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first, "keys under '" + path + "' must be names");
      const std::string k = it->first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(it->first, "unknown key '" + join(path, k) + "' (allowed here: " + list + ")");
      }
    }
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  double number(const YAML::Node& n, const std::string& name) const {
    if (!n.IsScalar()) fail(n, "key '" + name + "' must be a number");
    double v = 0.0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(n, "key '" + name + "' must be a number, got '" + n.Scalar() + "'");
    }
    if (!std::isfinite(v)) fail(n, "key '" + name + "' must be finite");
    return v;
  }
  void num(const YAML::Node& map, const std::string& path, const char* key, double& out) const {
    const YAML::Node n = map[key];
    if (n) out = number(n, join(path, key));
  }
  void integer(const YAML::Node& map, const std::string& path, const char* key,
               int64_t& out) const {
    const YAML::Node n = map[key];
    if (!n) return;
    const std::string name = join(path, key);
    if (!n.IsScalar()) fail(n, "key '" + name + "' must be an integer");
    try {
      out = n.as<int64_t>();
    } catch (const YAML::Exception&) {
      fail(n, "key '" + name + "' must be an integer, got '" + n.Scalar() + "'");
    }
  }
  void boolean(const YAML::Node& map, const std::string& path, const char* key, bool& out) const {
    const YAML::Node n = map[key];
    if (!n) return;
    const std::string name = join(path, key);
    if (!n.IsScalar()) fail(n, "key '" + name + "' must be true or false");
    try {
      out = n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(n, "key '" + name + "' must be true or false, got '" + n.Scalar() + "'");
    }
  }
  std::string text(const YAML::Node& map, const std::string& path, const char* key,
                   const std::string& def) const {
    const YAML::Node n = map[key];
    if (!n) return def;
    if (!n.IsScalar()) fail(n, "key '" + join(path, key) + "' must be a string");
    return n.Scalar();
  }
  std::vector<double> list(const YAML::Node& n, const std::string& name, size_t min_size,
                           size_t max_size) const {
    const std::string want = min_size == max_size
                                 ? std::to_string(min_size)
                                 : std::to_string(min_size) + " to " + std::to_string(max_size);
    if (!n.IsSequence() || n.size() < min_size || n.size() > max_size)
      fail(n, "key '" + name + "' must be a list of " + want + " numbers");
    std::vector<double> v;
    for (size_t i = 0; i < n.size(); ++i)
      v.push_back(number(n[i], name + "[" + std::to_string(i) + "]"));
    return v;
  }
  void vec3(const YAML::Node& map, const std::string& path, const char* key, Vec3& out) const {
    const YAML::Node n = map[key];
    if (!n) return;
    const auto v = list(n, join(path, key), 3, 3);
    out = Vec3(v[0], v[1], v[2]);
  }
  void vec2(const YAML::Node& map, const std::string& path, const char* key, Vec2& out) const {
    const YAML::Node n = map[key];
    if (!n) return;
    const auto v = list(n, join(path, key), 2, 2);
    out = Vec2(v[0], v[1]);
  }

 private:
  std::string file_;
};

int toInt(const Reader& r, const YAML::Node& at, const std::string& name, double v) {
  if (v != std::floor(v) || std::abs(v) > 1e9) r.fail(at, "key '" + name + "' must hold integers");
  return static_cast<int>(v);
}

void readCamera(const Reader& r, const YAML::Node& n, SynthConfig& c) {
  const std::string P = "camera";
  r.keys(n, P,
         {"preset", "width", "height", "fx", "fy", "cx", "cy", "distortion_model", "distortion"});
  c.camera_preset = r.text(n, P, "preset", "davis346");
  try {
    c.camera = cameraPreset(c.camera_preset);
  } catch (const std::invalid_argument& e) {
    r.fail(n["preset"], std::string("key 'camera.preset': ") + e.what());
  }
  int64_t w = c.camera.width, h = c.camera.height;
  r.integer(n, P, "width", w);
  r.integer(n, P, "height", h);
  if (w < 1 || h < 1 || w > 4096 || h > 4096 || w * h > 4 * 1024 * 1024)
    r.fail(n, "keys 'camera.width' and 'camera.height' must be in [1, 4096] with at most 4 Mpx");
  c.camera.width = static_cast<int>(w);
  c.camera.height = static_cast<int>(h);
  r.num(n, P, "fx", c.camera.fx);
  r.num(n, P, "fy", c.camera.fy);
  r.num(n, P, "cx", c.camera.cx);
  r.num(n, P, "cy", c.camera.cy);
  const std::string model = r.text(n, P, "distortion_model", toString(c.camera.distortion));
  try {
    c.camera.distortion = parseDistortionModel(model);
  } catch (const std::invalid_argument& e) {
    r.fail(n["distortion_model"], std::string("key 'camera.distortion_model': ") + e.what());
  }
  if (n["distortion"]) {
    const auto d = r.list(n["distortion"], "camera.distortion", 0, 5);
    c.camera.coeffs = {0, 0, 0, 0, 0};
    for (size_t i = 0; i < d.size(); ++i) c.camera.coeffs[i] = d[i];
  }
}

PlaneSpec readPlane(const Reader& r, const YAML::Node& n, const std::string& P) {
  PlaneSpec s;
  if (!n.IsMap()) r.fail(n, "key '" + P + "' must be a mapping");
  const std::string tex = r.text(n, P, "texture", "");
  if (tex.empty())
    r.fail(n, "key '" + P + ".texture' is required (chessboard, rectangles, segments)");
  try {
    s.texture = parseTextureKind(tex);
  } catch (const std::invalid_argument& e) {
    r.fail(n["texture"], "key '" + P + ".texture': " + e.what());
  }
  std::vector<std::string> allowed = {"texture", "position", "rotation"};
  if (s.texture == TextureKind::Chessboard) {
    allowed.insert(allowed.end(), {"square", "squares", "dark", "light"});
  } else {
    allowed.insert(allowed.end(), {"size", "base", "count", "intensity_range", "seed"});
    if (s.texture == TextureKind::Rectangles)
      allowed.insert(allowed.end(), {"size_range", "random_angle"});
    else
      allowed.insert(allowed.end(), {"length_range", "width_range"});
  }
  r.keys(n, P, allowed);
  r.vec3(n, P, "position", s.position);
  r.vec3(n, P, "rotation", s.rotation);
  r.num(n, P, "square", s.square);
  if (n["squares"]) {
    const auto q = r.list(n["squares"], P + ".squares", 2, 2);
    s.columns = toInt(r, n["squares"], P + ".squares", q[0]);
    s.rows = toInt(r, n["squares"], P + ".squares", q[1]);
  }
  r.num(n, P, "dark", s.dark);
  r.num(n, P, "light", s.light);
  if (n["size"]) {
    const auto q = r.list(n["size"], P + ".size", 2, 2);
    s.width = q[0];
    s.height = q[1];
  }
  r.num(n, P, "base", s.base);
  int64_t count = s.count;
  r.integer(n, P, "count", count);
  if (count < 0 || count > 5000) r.fail(n["count"], "key '" + P + ".count' must be in [0, 5000]");
  s.count = static_cast<int>(count);
  r.vec2(n, P, "intensity_range", s.intensity_range);
  r.vec2(n, P, "size_range", s.size_range);
  r.vec2(n, P, "length_range", s.size_range);
  r.vec2(n, P, "width_range", s.width_range);
  r.boolean(n, P, "random_angle", s.random_angle);
  r.integer(n, P, "seed", s.seed);
  const std::string err = s.validate();
  if (!err.empty()) r.fail(n, "key '" + P + "': " + err);
  return s;
}

void readTrajectory(const Reader& r, const YAML::Node& n, SynthConfig& c) {
  const std::string P = "trajectory";
  TrajectorySpec& t = c.trajectory;
  const std::string type = r.text(n, P, "type", "constant_twist");
  try {
    t.kind = parseTrajectoryKind(type);
  } catch (const std::invalid_argument& e) {
    r.fail(n["type"], std::string("key 'trajectory.type': ") + e.what());
  }
  std::vector<std::string> allowed = {"type", "initial_position", "initial_rotation"};
  if (t.kind == TrajectoryKind::Piecewise)
    allowed.push_back("segments");
  else
    allowed.insert(allowed.end(), {"v", "w"});
  if (t.kind == TrajectoryKind::Sinusoid)
    allowed.insert(allowed.end(), {"amplitude_v", "amplitude_w", "frequency"});
  r.keys(n, P, allowed);
  r.vec3(n, P, "v", t.v);
  r.vec3(n, P, "w", t.w);
  r.vec3(n, P, "amplitude_v", t.amplitude_v);
  r.vec3(n, P, "amplitude_w", t.amplitude_w);
  r.num(n, P, "frequency", t.frequency);
  r.vec3(n, P, "initial_position", t.initial.p);
  Vec3 rot = Vec3::Zero();
  r.vec3(n, P, "initial_rotation", rot);
  t.initial.R = so3::exp(rot);
  if (t.kind == TrajectoryKind::Piecewise) {
    const YAML::Node segs = n["segments"];
    if (!segs || !segs.IsSequence() || segs.size() == 0)
      r.fail(segs ? segs : n, "key 'trajectory.segments' must be a non-empty list");
    for (size_t i = 0; i < segs.size(); ++i) {
      const std::string SP = P + ".segments[" + std::to_string(i) + "]";
      r.keys(segs[i], SP, {"duration", "v", "w"});
      TwistSegment s;
      if (!segs[i]["duration"]) r.fail(segs[i], "key '" + SP + ".duration' is required");
      r.num(segs[i], SP, "duration", s.duration);
      r.vec3(segs[i], SP, "v", s.v);
      r.vec3(segs[i], SP, "w", s.w);
      t.segments.push_back(s);
    }
  }
  const std::string err = t.validate();
  if (!err.empty()) r.fail(n, "key 'trajectory': " + err);
}

void readEvents(const Reader& r, const YAML::Node& n, RenderOptions& o) {
  const std::string P = "events";
  r.keys(n, P,
         {"contrast_on", "contrast_off", "contrast_sigma", "refractory", "noise_rate", "log_eps",
          "max_step_px", "max_step", "smoothing_px", "threads"});
  r.num(n, P, "contrast_on", o.contrast_on);
  r.num(n, P, "contrast_off", o.contrast_off);
  r.num(n, P, "contrast_sigma", o.contrast_sigma);
  r.num(n, P, "refractory", o.refractory);
  r.num(n, P, "noise_rate", o.noise_rate);
  r.num(n, P, "log_eps", o.log_eps);
  r.num(n, P, "max_step_px", o.max_step_px);
  r.num(n, P, "max_step", o.max_step);
  r.num(n, P, "smoothing_px", o.smoothing_px);
  int64_t th = o.threads;
  r.integer(n, P, "threads", th);
  if (th < 1 || th > 64) r.fail(n["threads"], "key 'events.threads' must be in [1, 64]");
  o.threads = static_cast<int>(th);
  const std::string err = o.validate();
  if (!err.empty()) r.fail(n, "key 'events': " + err);
}

Mat3 rotationFrom(const Reader& r, const YAML::Node& n, const std::string& name) {
  const auto v = r.list(n, name, 9, 9);
  Mat3 R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = v[i];
  if ((R.transpose() * R - Mat3::Identity()).norm() > 1e-6 || R.determinant() < 0.0)
    r.fail(n, "key '" + name + "' must be a rotation matrix (row-major 3x3)");
  return R;
}

void readImu(const Reader& r, const YAML::Node& n, ImuOptions& o) {
  const std::string P = "imu";
  r.keys(n, P,
         {"rate", "gyro_noise", "gyro_bias", "accel_noise", "accel_bias", "R_cam_imu", "gravity"});
  r.num(n, P, "rate", o.rate);
  r.num(n, P, "gyro_noise", o.gyro_noise);
  r.vec3(n, P, "gyro_bias", o.gyro_bias);
  r.num(n, P, "accel_noise", o.accel_noise);
  r.vec3(n, P, "accel_bias", o.accel_bias);
  if (n["R_cam_imu"]) o.R_cam_imu = rotationFrom(r, n["R_cam_imu"], "imu.R_cam_imu");
  r.vec3(n, P, "gravity", o.gravity);
  const std::string err = o.validate();
  if (!err.empty()) r.fail(n, "key 'imu': " + err);
}

void readGroundTruth(const Reader& r, const YAML::Node& n, GroundTruthOptions& o) {
  const std::string P = "groundtruth";
  r.keys(n, P, {"rate", "T_body_cam"});
  r.num(n, P, "rate", o.rate);
  if (n["T_body_cam"]) {
    const auto v = r.list(n["T_body_cam"], "groundtruth.T_body_cam", 16, 16);
    Mat3 R;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R(i, j) = v[4 * i + j];
    if ((R.transpose() * R - Mat3::Identity()).norm() > 1e-6 || R.determinant() < 0.0 ||
        v[12] != 0.0 || v[13] != 0.0 || v[14] != 0.0 || v[15] != 1.0)
      r.fail(n["T_body_cam"],
             "key 'groundtruth.T_body_cam' must be a rigid transform (row-major 4x4)");
    o.T_body_cam.R = R;
    o.T_body_cam.p = Vec3(v[3], v[7], v[11]);
  }
  const std::string err = o.validate();
  if (!err.empty()) r.fail(n, "key 'groundtruth': " + err);
}

}  // namespace

SynthConfig loadSynthConfig(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::invalid_argument(path + ": cannot open the file");
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(path + ":" + std::to_string(e.mark.line + 1) +
                                ": YAML syntax error: " + e.msg);
  }
  Reader r(path);
  if (!root.IsMap())
    throw std::invalid_argument(path + ": expected a YAML mapping at the top level");
  SynthConfig c;
  c.source = path;
  r.keys(root, "",
         {"seed", "duration", "background", "camera", "planes", "trajectory", "events", "imu",
          "groundtruth"});
  int64_t seed = 1;
  r.integer(root, "", "seed", seed);
  if (seed < 0) r.fail(root["seed"], "key 'seed' must be >= 0");
  c.seed = static_cast<uint64_t>(seed);
  r.num(root, "", "duration", c.duration);
  if (!(c.duration > 0.0) || c.duration > 3600.0)
    r.fail(root["duration"], "key 'duration' must be in (0, 3600] s");
  r.num(root, "", "background", c.background);
  if (c.background < 0.0 || c.background > 1.0)
    r.fail(root["background"], "key 'background' must be in [0, 1]");
  c.camera = cameraPreset("davis346");
  if (root["camera"]) readCamera(r, root["camera"], c);
  const YAML::Node planes = root["planes"];
  if (!planes || !planes.IsSequence() || planes.size() == 0)
    r.fail(planes ? planes : root, "key 'planes' must be a non-empty list of planes");
  if (planes.size() > 16) r.fail(planes, "key 'planes': at most 16 planes");
  for (size_t i = 0; i < planes.size(); ++i)
    c.planes.push_back(readPlane(r, planes[i], "planes[" + std::to_string(i) + "]"));
  if (root["trajectory"]) readTrajectory(r, root["trajectory"], c);
  if (root["events"]) readEvents(r, root["events"], c.events);
  if (root["imu"]) readImu(r, root["imu"], c.imu);
  if (root["groundtruth"]) readGroundTruth(r, root["groundtruth"], c.groundtruth);
  const std::string err = c.validate();
  if (!err.empty()) throw std::invalid_argument(path + ": " + err);
  return c;
}

}  // namespace celc::sim
