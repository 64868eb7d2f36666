// SCENE.yaml of `celc synth`: its schema (core/fields.hpp) and loader
// (docs/simulation.md, config/scenes/).
#include <cmath>
#include <string>
#include <vector>

#include "celc/core/yaml.hpp"
#include "celc/geometry/so3.hpp"
#include "celc/sim/render_sequence.hpp"

namespace celc {

namespace {

bool isRotation(const Mat3& R) {
  return (R.transpose() * R - Mat3::Identity()).norm() <= 1e-6 && R.determinant() > 0.0;
}

/// `camera:`: a preset (its size and intrinsics), then any field of it overridden.
void describeCamera(FieldVisitor& v, SynthConfig& c) {
  std::string preset = c.camera_preset;
  v.choice({"preset", "", "size and intrinsics to start from"}, preset, {"davis346", "davis240"});
  if (preset != c.camera_preset) {
    c.camera_preset = preset;
    c.camera = cameraPreset(preset);
  }
  describe(v, c.camera);
  if (v.reading() && (c.camera.width < 1 || c.camera.height < 1 || c.camera.width > 4096 ||
                      c.camera.height > 4096 || c.camera.width * c.camera.height > 4 * 1024 * 1024))
    v.fail("width", "camera.width and camera.height must be in [1, 4096] with at most 4 Mpx");
}

/// One textured plane; the keys that apply depend on its texture.
void describePlane(FieldVisitor& v, PlaneSpec& s) {
  v.require("texture");
  v.enumeration({"texture", "", "what is printed on the plane"}, s.texture,
                {TextureKind::Chessboard, TextureKind::Rectangles, TextureKind::Segments});
  v.field({"position", "m", "plane centre in the world", anyFinite()}, s.position);
  v.field({"rotation", "rad", "axis-angle of R_world_plane", anyFinite()}, s.rotation);
  if (s.texture == TextureKind::Chessboard) {
    v.field({"square", "m", "side of a square", above(0)}, s.square);
    std::vector<double> squares{double(s.columns), double(s.rows)};
    v.field({"squares", "", "squares along u and v", within(1, 100000)}, squares, {2});
    for (double q : squares)
      if (q != std::floor(q) || std::abs(q) > 1e6) v.fail("squares", "expected two integers");
    s.columns = static_cast<int>(squares[0]);
    s.rows = static_cast<int>(squares[1]);
    v.field({"dark", "-", "intensity of the dark squares", within(0, 1)}, s.dark);
    v.field({"light", "-", "intensity of the light squares", within(0, 1)}, s.light);
  } else {
    std::vector<double> size{s.width, s.height};
    v.field({"size", "m", "plane extent along u and v", above(0)}, size, {2});
    s.width = size[0];
    s.height = size[1];
    v.field({"base", "-", "intensity under the shapes", within(0, 1)}, s.base);
    v.field({"count", "", "number of shapes", within(0, 5000)}, s.count);
    v.field({"intensity_range", "-", "shape intensities drawn from this range", within(0, 1)}, s.intensity_range);
    v.field({"seed", "", "shape layout seed (< 0: from the scene seed)"}, s.seed);
    if (s.texture == TextureKind::Rectangles) {
      v.field({"size_range", "m", "rectangle sides drawn from this range", above(0)}, s.size_range);
      v.field({"random_angle", "", "rotate each rectangle by a uniform angle"}, s.random_angle);
    } else {
      v.field({"length_range", "m", "segment lengths drawn from this range", above(0)}, s.size_range);
      v.field({"width_range", "m", "segment thickness drawn from this range", above(0)}, s.width_range);
    }
  }
  if (v.reading()) failOnFirstProblem(v, s.validate());
}

void describeTrajectory(FieldVisitor& v, TrajectorySpec& t) {
  v.enumeration({"type", "", "the camera's motion"}, t.kind,
                {TrajectoryKind::ConstantTwist, TrajectoryKind::Piecewise, TrajectoryKind::Sinusoid,
                  TrajectoryKind::ConstantAcceleration});
  v.field({"initial_position", "m", "camera position at t = 0 (world)", anyFinite()}, t.initial.p);
  Vec3 rotation = so3::log(t.initial.R);
  v.field({"initial_rotation", "rad", "axis-angle of the camera's orientation at t = 0", anyFinite()}, rotation);
  t.initial.R = so3::exp(rotation);
  if (t.kind == TrajectoryKind::Piecewise) {
    v.require("segments");
    v.items({"segments", "", "constant twists one after the other"}, t.segments,
            [](FieldVisitor& s, TwistSegment& seg) {
              s.require("duration");
              s.field({"duration", "s", "segment length", above(0)}, seg.duration);
              s.field({"v", "m/s", "linear velocity, camera frame", anyFinite()}, seg.v);
              s.field({"w", "rad/s", "angular velocity, camera frame", anyFinite()}, seg.w);
            });
    if (v.reading() && t.segments.empty()) v.fail("segments", "expected a non-empty list");
  } else {
    v.field({"v", "m/s", "linear velocity, camera frame (sinusoid: mean; constant_acceleration: at t = 0)",
             anyFinite()},
            t.v);
    v.field({"w", "rad/s", "angular velocity, camera frame (sinusoid: mean)", anyFinite()}, t.w);
  }
  if (t.kind == TrajectoryKind::Sinusoid) {
    v.field({"amplitude_v", "m/s", "amplitude of v", anyFinite()}, t.amplitude_v);
    v.field({"amplitude_w", "rad/s", "amplitude of w", anyFinite()}, t.amplitude_w);
    v.field({"frequency", "Hz", "frequency of both", withinAbove(0, 1e4)}, t.frequency);
  }
  if (t.kind == TrajectoryKind::ConstantAcceleration)
    v.field({"acceleration", "m/s^2", "constant in the world, given in the camera frame at t = 0", anyFinite()},
            t.acceleration);
  if (v.reading()) failOnFirstProblem(v, t.validate());
}

}  // namespace

std::string PlaneSpec::validate() const {
  PlaneSpec copy = *this;
  std::string e = rangeProblems(Describe([&](FieldVisitor& v) { describePlane(v, copy); }));
  if (texture == TextureKind::Chessboard) return e;
  if (!(size_range.y() >= size_range.x())) e += "size_range: must be min <= max; ";
  if (texture == TextureKind::Segments && !(width_range.y() >= width_range.x()))
    e += "width_range: must be min <= max; ";
  if (!(intensity_range.y() >= intensity_range.x())) e += "intensity_range: must be min <= max; ";
  return e;
}

std::string TrajectorySpec::validate() const {
  TrajectorySpec copy = *this;
  std::string e = rangeProblems(Describe([&](FieldVisitor& v) { describeTrajectory(v, copy); }));
  if (!initial.R.allFinite()) e += "initial_rotation: must be finite; ";
  if (kind == TrajectoryKind::Piecewise && segments.empty()) e += "segments: at least one; ";
  return e;
}

void describe(FieldVisitor& v, RenderOptions& o) {
  v.field({"contrast_on", "log I", "ON threshold C+", above(0)}, o.contrast_on);
  v.field({"contrast_off", "log I", "OFF threshold C-", above(0)}, o.contrast_off);
  v.field({"contrast_sigma", "log I", "per-pixel threshold mismatch, std", atLeast(0)}, o.contrast_sigma);
  v.field({"refractory", "s", "refractory period (0 = off)", withinBelow(0, 10)}, o.refractory);
  v.field({"noise_rate", "Hz", "background events per pixel, <= 1000", within(0, 1000)}, o.noise_rate);
  v.field({"log_eps", "-", "eps in L = log(eps + I)", above(0)}, o.log_eps);
  v.field({"max_step_px", "px", "largest image motion per render step", above(0)}, o.max_step_px);
  v.field({"max_step", "s", "largest render step", above(0)}, o.max_step);
  v.field({"min_step", "s", "smallest render step", above(0)}, o.min_step);
  v.field({"smoothing_px", "px", "width of the anti-aliasing ramp across edges", withinAbove(0, 100)},
          o.smoothing_px);
  v.field({"skip_static", "", "skip render steps where nothing moves"}, o.skip_static);
  v.field({"threads", "", "worker threads, [1, 64]", within(1, 64)}, o.threads);
  if (v.reading())
    if (const std::string err = o.validate(); !err.empty()) v.fail("", err);
}

void describe(FieldVisitor& v, ImuOptions& o) {
  v.field({"rate", "Hz", "sample rate", withinAbove(0, 1e6)}, o.rate);
  v.field({"gyro_noise", "rad/s/sqrt(Hz)", "gyro white-noise density", atLeast(0)}, o.gyro_noise);
  v.field({"gyro_bias", "rad/s", "constant gyro bias", anyFinite()}, o.gyro_bias);
  v.field({"accel_noise", "m/s^2/sqrt(Hz)", "accelerometer white-noise density", atLeast(0)}, o.accel_noise);
  v.field({"accel_bias", "m/s^2", "constant accelerometer bias", anyFinite()}, o.accel_bias);
  const Mat3 transposed = o.R_cam_imu.transpose();  // its column-major storage is row-major R
  std::vector<double> R(transposed.data(), transposed.data() + 9);
  v.field({"R_cam_imu", "-", "rotation IMU -> camera, row-major 3x3"}, R, {9});
  const Mat3 read = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R.data());
  if (!isRotation(read)) v.fail("R_cam_imu", "must be a rotation matrix (row-major 3x3)");
  o.R_cam_imu = read;
  v.field({"gravity", "m/s^2", "gravity in the world frame", anyFinite()}, o.gravity);
  v.field({"still_before_s", "s", "the IMU starts this long before the motion, the camera at rest",
           within(0, 60)}, o.still_before_s);
  if (v.reading())
    if (const std::string err = o.validate(); !err.empty()) v.fail("", err);
}

void describe(FieldVisitor& v, GroundTruthOptions& o) {
  v.field({"rate", "Hz", "pose rate", withinAbove(0, 1e6)}, o.rate);
  Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>::Identity();
  T.topLeftCorner<3, 3>() = o.T_body_cam.R;
  T.topRightCorner<3, 1>() = o.T_body_cam.p;
  std::vector<double> flat(T.data(), T.data() + 16);
  v.field({"T_body_cam", "m", "camera pose in the body frame, row-major 4x4"}, flat, {16});
  T = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(flat.data());
  if (!isRotation(T.topLeftCorner<3, 3>()) || T(3, 0) != 0.0 || T(3, 1) != 0.0 || T(3, 2) != 0.0 || T(3, 3) != 1.0)
    v.fail("T_body_cam", "must be a rigid transform (row-major 4x4)");
  o.T_body_cam.R = T.topLeftCorner<3, 3>();
  o.T_body_cam.p = T.topRightCorner<3, 1>();
  if (v.reading())
    if (const std::string err = o.validate(); !err.empty()) v.fail("", err);
}

namespace {
/// The scene's own scalars (the sections have their own describe()).
void describeSceneScalars(FieldVisitor& v, SynthConfig& c) {
  v.field({"seed", "", "seed of the textures, thresholds and noise"}, c.seed);
  v.field({"duration", "s", "length of the sequence", withinAbove(0, 3600)}, c.duration);
  v.field({"background", "-", "intensity where no plane is seen", within(0, 1)}, c.background);
}

/// describeSceneScalars' range problems of c.
std::string sceneScalarProblems(const SynthConfig& c) {
  SynthConfig copy = c;
  return rangeProblems(Describe([&](FieldVisitor& v) { describeSceneScalars(v, copy); }));
}
}  // namespace

std::string SynthConfig::validate() const {
  std::string e = sceneScalarProblems(*this);
  if (planes.empty()) e += "the scene needs at least one plane; ";
  if (planes.size() > 16) e += "at most 16 planes; ";
  for (size_t i = 0; i < planes.size(); ++i) {
    const std::string p = planes[i].validate();
    if (!p.empty()) e += "planes[" + std::to_string(i) + "]: " + p;
  }
  const std::string c = camera.validate();
  if (!c.empty()) e += "camera: " + c;
  const std::string t = trajectory.validate();
  if (!t.empty()) e += "trajectory: " + t;
  const std::string r = events.validate();
  if (!r.empty()) e += "events: " + r;
  e += inSection("imu", imu.validate());
  e += inSection("groundtruth", groundtruth.validate());
  return e;
}

void describe(FieldVisitor& v, SynthConfig& c) {
  describeSceneScalars(v, c);
  if (v.reading()) failOnFirstProblem(v, sceneScalarProblems(c));
  v.section({"camera", "", "the event camera"}, [&](FieldVisitor& s) { describeCamera(s, c); });
  v.require("planes");
  v.items({"planes", "", "textured planes of the scene (1 to 16)"}, c.planes, describePlane);
  if (c.planes.empty() || c.planes.size() > 16) v.fail("planes", "expected a non-empty list of at most 16 planes");
  v.section({"trajectory", "", "the camera's motion"}, [&](FieldVisitor& s) { describeTrajectory(s, c.trajectory); });
  v.section({"events", "", "the event model"}, [&](FieldVisitor& s) { describe(s, c.events); });
  v.section({"imu", "", "the simulated IMU"}, [&](FieldVisitor& s) { describe(s, c.imu); });
  v.section({"groundtruth", "", "the pose file"}, [&](FieldVisitor& s) { describe(s, c.groundtruth); });
}

namespace {
// The defaults (the davis346 camera), then the document `read` applies, validated.
template <class Read>
SynthConfig synthConfig(const std::string& origin, Read&& read) {
  SynthConfig c;
  c.source = origin;
  c.camera = cameraPreset(c.camera_preset);
  read([&](FieldVisitor& v) { describe(v, c); });
  if (const std::string err = c.validate(); !err.empty()) throw ConfigError(origin + ": " + err);
  return c;
}
}  // namespace

SynthConfig loadSynthConfig(const std::string& path) {
  return synthConfig(path, [&](const Describe& d) { readYamlFile(path, d); });
}

SynthConfig parseSynthConfig(const std::string& yaml, const std::string& origin) {
  return synthConfig(origin, [&](const Describe& d) { readYaml(yaml, origin, d); });
}

}  // namespace celc
