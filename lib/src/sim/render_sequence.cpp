#include "celc/sim/render_sequence.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>

#include "celc/io/sequence_layout.hpp"
#include "celc/io/writers.hpp"

namespace celc {

namespace fs = std::filesystem;
namespace file = sequence_file;

std::string ImuOptions::validate() const { return rangeProblemsOf(*this); }

std::string GroundTruthOptions::validate() const { return rangeProblemsOf(*this); }


CameraModel cameraPreset(const std::string& name) {
  CameraModel c;
  if (name == "davis346") {
    c.width = 346;
    c.height = 260;
    c.fx = c.fy = 320.0;
    c.cx = 173.0;
    c.cy = 130.0;
  } else if (name == "davis240") {
    c.width = 240;
    c.height = 180;
    c.fx = c.fy = 200.0;
    c.cx = 120.0;
    c.cy = 90.0;
  } else {
    throw std::invalid_argument("unknown camera preset '" + name +
                                "' (expected davis346 or davis240)");
  }
  c.distortion = DistortionModel::None;
  return c;
}

std::vector<ImuSample> simulateImu(const Trajectory& trajectory, const ImuOptions& options,
                                   double t0, double t1, uint64_t seed) {
  std::vector<ImuSample> out;
  if (!(t1 >= t0)) return out;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  const double sg = options.gyro_noise * std::sqrt(options.rate);
  const double sa = options.accel_noise * std::sqrt(options.rate);
  const Mat3 R_imu_cam = options.R_cam_imu.transpose();
  const size_t n = static_cast<size_t>(std::floor((t1 - t0) * options.rate + 1e-9)) + 1;
  out.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    const double t = t0 + static_cast<double>(k) / options.rate;
    const bool at_rest = t < 0.0 && options.still_before_s > 0.0;
    const RigidPose T = trajectory.pose(at_rest ? 0.0 : t);
    const Vec3 v = at_rest ? Vec3::Zero() : trajectory.linearVelocity(t);
    const Vec3 w = at_rest ? Vec3::Zero() : trajectory.angularVelocity(t);
    const Vec3 rate = at_rest ? Vec3::Zero() : trajectory.linearVelocityRate(t);
    const Vec3 f_cam = rate + w.cross(v) - T.R.transpose() * options.gravity;
    ImuSample s;
    s.t = t;
    s.gyro = R_imu_cam * w + options.gyro_bias + sg * Vec3(N(rng), N(rng), N(rng));
    s.accel = R_imu_cam * f_cam + options.accel_bias + sa * Vec3(N(rng), N(rng), N(rng));
    out.push_back(s);
  }
  return out;
}

std::vector<PoseSample> groundTruthPoses(const Trajectory& trajectory,
                                         const GroundTruthOptions& options, double t0, double t1) {
  std::vector<PoseSample> out;
  if (!(t1 >= t0)) return out;
  const RigidPose T_cam_body = options.T_body_cam.inverse();
  const size_t n = static_cast<size_t>(std::floor((t1 - t0) * options.rate + 1e-9)) + 1;
  for (size_t k = 0; k < n; ++k) {
    const double t = t0 + static_cast<double>(k) / options.rate;
    const RigidPose T = trajectory.pose(t) * T_cam_body;
    PoseSample p;
    p.t = t;
    p.position = T.p;
    p.orientation = Eigen::Quaterniond(T.R).normalized();
    if (p.orientation.w() < 0.0) p.orientation.coeffs() *= -1.0;
    out.push_back(p);
  }
  return out;
}

namespace {

/// A file written under a temporary name, renamed by commit().
class PartialFile {
 public:
  PartialFile(const fs::path& dir, const std::string& name)
      : final_(dir / name), temp_(dir / ("." + name + ".partial")) {
    f_ = std::fopen(temp_.c_str(), "wb");
    if (!f_) throw std::runtime_error(temp_.string() + ": cannot open for writing");
  }
  ~PartialFile() {
    if (f_) std::fclose(f_);
  }
  PartialFile(const PartialFile&) = delete;
  PartialFile& operator=(const PartialFile&) = delete;
  void write(const char* data, size_t n) {
    if (n && std::fwrite(data, 1, n, f_) != n)
      throw std::runtime_error(temp_.string() + ": write failed (disk full?)");
  }
  void write(const std::string& s) { write(s.data(), s.size()); }
  void close() {
    if (std::fclose(f_) != 0) {
      f_ = nullptr;
      throw std::runtime_error(temp_.string() + ": close failed");
    }
    f_ = nullptr;
  }
  void commit() {
    std::error_code ec;
    fs::rename(temp_, final_, ec);
    if (ec) throw std::runtime_error(final_.string() + ": cannot rename: " + ec.message());
  }

 private:
  fs::path final_, temp_;
  std::FILE* f_ = nullptr;
};

std::string num(double x) {
  std::ostringstream s;
  s << std::setprecision(12) << x;
  return s.str();
}
std::string vec(const Vec3& v) {
  return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}
std::string mat(const Mat3& R) {
  std::string s = "[";
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s += num(R(i, j)) + (i == 2 && j == 2 ? "]" : ", ");
  return s;
}

std::string calibYaml(const SynthConfig& c) {
  std::ostringstream y;
  const CameraModel& k = c.camera;
  y << "# Calibration of a sequence simulated by `celc synth` (schema: docs/formats.md).\n"
    << "camera:\n"
    << "  width: " << k.width << "            # [px]\n"
    << "  height: " << k.height << "           # [px]\n"
    << "  fx: " << num(k.fx) << "             # [px]\n"
    << "  fy: " << num(k.fy) << "             # [px]\n"
    << "  cx: " << num(k.cx) << "             # [px]\n"
    << "  cy: " << num(k.cy) << "             # [px]\n"
    << "  distortion_model: " << toString(k.distortion) << "\n"
    << "  distortion: [" << num(k.coeffs[0]) << ", " << num(k.coeffs[1]) << ", " << num(k.coeffs[2])
    << ", " << num(k.coeffs[3]) << ", " << num(k.coeffs[4]) << "]\n"
    << "imu:\n"
    << "  R_cam_imu: " << mat(c.imu.R_cam_imu) << "   # row-major\n"
    << "  time_offset: 0.0    # [s]\n"
    << "body:\n"
    << "  T_body_cam: [";
  const RigidPose& T = c.groundtruth.T_body_cam;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) y << num(j < 3 ? T.R(i, j) : T.p(i)) << ", ";
  y << "0, 0, 0, 1]   # row-major 4x4\n";
  return y.str();
}

std::string twistYaml(const SynthConfig& c, const SynthSummary& s) {
  const TrajectorySpec& t = c.trajectory;
  std::ostringstream y;
  y << "# True motion of the simulated camera (celc synth). Camera frame: x right, y down,\n"
    << "# z forward. v [m/s], w [rad/s] are the body (camera-frame) twist; over a constant\n"
    << "# twist the pose relative to t_ref is R = exp(w^ tau), p = J_l(w tau) v tau.\n"
    << "source: \"" << c.source << "\"\n"
    << "seed: " << c.seed << "\n"
    << "duration: " << num(c.duration) << "        # [s]\n"
    << "type: " << toString(t.kind) << "\n";
  if (t.kind != TrajectoryKind::Piecewise) {
    y << "v: " << vec(t.v) << "     # [m/s]"
      << (t.kind == TrajectoryKind::Sinusoid ? " mean" : t.kind == TrajectoryKind::ConstantAcceleration ? " at t = 0" : "")
      << "\n"
      << "w: " << vec(t.w) << "     # [rad/s]\n";
    if (t.kind == TrajectoryKind::ConstantTwist && t.v.norm() > 0.0)
      y << "v_direction: " << vec(t.v.normalized()) << "   # unit\n";
  }
  if (t.kind == TrajectoryKind::Sinusoid)
    y << "amplitude_v: " << vec(t.amplitude_v) << "   # v(t) = v + amplitude_v sin(2 pi f t)\n"
      << "amplitude_w: " << vec(t.amplitude_w) << "   # w(t) = w + amplitude_w sin(2 pi f t)\n"
      << "frequency: " << num(t.frequency) << "   # [Hz]\n";
  if (t.kind == TrajectoryKind::ConstantAcceleration)
    y << "acceleration: " << vec(t.acceleration)
      << "   # [m/s^2], world-fixed, camera frame at t = 0: v(t) = exp(w^ t)^T (v + a t)\n";
  if (t.kind == TrajectoryKind::Piecewise) {
    y << "segments:\n";
    double t0 = 0.0;
    for (const auto& seg : t.segments) {
      y << "  - {t_start: " << num(t0) << ", t_end: " << num(t0 + seg.duration)
        << ", v: " << vec(seg.v) << ", w: " << vec(seg.w) << "}\n";
      t0 += seg.duration;
    }
  }
  y << "initial_R_world_cam: " << mat(t.initial.R) << "   # row-major\n"
    << "initial_p_world_cam: " << vec(t.initial.p) << "   # [m]\n"
    << "stats:\n"
    << "  events: " << s.events << "\n"
    << "  events_on: " << s.stats.events_on << "\n"
    << "  events_off: " << s.stats.events_off << "\n"
    << "  events_noise: " << s.stats.events_noise << "\n"
    << "  refractory_dropped: " << s.stats.refractory_dropped << "\n"
    << "  renders: " << s.stats.renders << "\n"
    << "  min_step: " << num(s.stats.min_step) << "    # [s]\n"
    << "  max_step: " << num(s.stats.max_step) << "    # [s]\n";
  return y.str();
}

}  // namespace

SynthSummary writeSequence(const SynthConfig& config, const std::string& dir_name,
                           const SynthProgress& progress) {
  const std::string err = config.validate();
  if (!err.empty()) throw std::invalid_argument(config.source + ": " + err);
  const auto wall0 = std::chrono::steady_clock::now();
  const fs::path dir(dir_name);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create directory: " + ec.message());
  // Remove a previous run's files first (events.txt first), so that an
  // interrupted run never leaves old and new files that look like one sequence.
  for (const char* name : simulatedSequenceFiles()) {
    fs::remove(dir / name, ec);
    if (ec) throw std::runtime_error((dir / name).string() + ": cannot remove: " + ec.message());
  }

  const Scene scene = Scene::build(config.planes, config.background, config.seed);
  const Trajectory trajectory(config.trajectory, config.duration + 0.1);
  RenderOptions ro = config.events;
  ro.seed = config.seed;
  RenderEventSimulator sim(scene, config.camera, trajectory, ro, 0.0);

  SynthSummary summary;
  summary.duration = config.duration;
  PartialFile events(dir, file::kEvents), labels(dir, file::kLabels);
  std::vector<SimEvent> buf;
  std::string ebuf, lbuf;
  const double slice = 0.01;  // [s] events are written every 10 ms of simulated time
  for (int64_t k = 1;; ++k) {
    // Slice ends k * slice (not accumulated sums: 0.1 stays 0.1).
    const double t_next = std::min(config.duration, static_cast<double>(k) * slice);
    buf.clear();
    sim.advanceTo(t_next, buf);
    ebuf.resize(buf.size() * (kEventLineMicrosMaxChars + 1));
    lbuf.resize(buf.size() * 12);  // int32 and a line end
    char* pe = ebuf.data();
    char* pl = lbuf.data();
    for (const SimEvent& e : buf) {
      pe = putEventLineMicros(pe, e.t_us, e.x, e.y, e.on);
      *pe++ = '\n';
      pl = std::to_chars(pl, pl + 11, e.label).ptr;
      *pl++ = '\n';
    }
    events.write(ebuf.data(), static_cast<size_t>(pe - ebuf.data()));
    labels.write(lbuf.data(), static_cast<size_t>(pl - lbuf.data()));
    summary.events += static_cast<int64_t>(buf.size());
    if (progress) progress(t_next, summary.events);
    if (t_next >= config.duration) break;
  }
  events.close();
  labels.close();
  summary.stats = sim.stats();

  {  // IMU
    const auto imu = simulateImu(trajectory, config.imu, -config.imu.still_before_s, config.duration, config.seed + 1);
    PartialFile f(dir, file::kImu);
    char line[256];
    for (const ImuSample& s : imu) {
      const int n =
          std::snprintf(line, sizeof line, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g\n", s.t, s.accel.x(),
                        s.accel.y(), s.accel.z(), s.gyro.x(), s.gyro.y(), s.gyro.z());
      f.write(line, static_cast<size_t>(n));
    }
    f.close();
    summary.imu_samples = static_cast<int64_t>(imu.size());
    f.commit();
  }
  {  // ground truth and true twist
    const auto poses = groundTruthPoses(trajectory, config.groundtruth, 0.0, config.duration);
    PartialFile f(dir, file::kGroundTruth), tw(dir, file::kTwist);
    char line[256];
    for (const PoseSample& p : poses) {
      const auto& q = p.orientation;
      int n =
          std::snprintf(line, sizeof line, "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", p.t,
                        p.position.x(), p.position.y(), p.position.z(), q.x(), q.y(), q.z(), q.w());
      f.write(line, static_cast<size_t>(n));
      const Vec3 v = trajectory.linearVelocity(p.t), w = trajectory.angularVelocity(p.t);
      n = std::snprintf(line, sizeof line, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g\n", p.t, v.x(),
                        v.y(), v.z(), w.x(), w.y(), w.z());
      tw.write(line, static_cast<size_t>(n));
    }
    f.close();
    tw.close();
    summary.poses = static_cast<int64_t>(poses.size());
    f.commit();
    tw.commit();
  }
  {  // calibration
    const CameraModel& k = config.camera;
    PartialFile f(dir, file::kCalibText);
    char line[512];
    const int n = std::snprintf(line, sizeof line, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                                k.fx, k.fy, k.cx, k.cy, k.coeffs[0], k.coeffs[1], k.coeffs[2],
                                k.coeffs[3], k.coeffs[4]);
    f.write(line, static_cast<size_t>(n));
    f.close();
    f.commit();
    PartialFile y(dir, file::kCalibYaml);
    y.write(calibYaml(config));
    y.close();
    y.commit();
  }
  {  // scene edges
    PartialFile f(dir, file::kEdges);
    char line[512];
    for (const SceneEdge& e : scene.edges()) {
      const int n = std::snprintf(line, sizeof line, "%d %.9g %.9g %.9g %.9g %.9g %.9g\n", e.id,
                                  e.p0.x(), e.p0.y(), e.p0.z(), e.p1.x(), e.p1.y(), e.p1.z());
      f.write(line, static_cast<size_t>(n));
    }
    f.close();
    f.commit();
  }
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  PartialFile y(dir, file::kTwistYaml);
  y.write(twistYaml(config, summary));
  y.close();
  // The event files last: a directory with events.txt is complete.
  labels.commit();
  y.commit();
  events.commit();
  return summary;
}

}  // namespace celc
