#include "celc/sim/peer_scene.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace celc {

CameraModel PeerSceneOptions::defaultCamera() {
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 320.0;
  c.cx = 320.0;
  c.cy = 240.0;
  return c;
}

void describe(FieldVisitor& v, PeerSceneOptions& o) {
  v.field({"n_lines", "", "3D segments (clusters)", atLeast(1)}, o.n_lines);
  v.field({"events_per_line", "events", "events per segment, outliers included", atLeast(2)}, o.events_per_line);
  v.field({"duration", "s", "window length, centred on t_ref", above(0)}, o.duration);
  v.field({"t_ref", "s", "reference time", anyFinite()}, o.t_ref);
  v.field({"speed", "m/s", "|v|", atLeast(0)}, o.speed);
  v.field({"omega_deg_s", "deg/s", "|w|", atLeast(0)}, o.omega_deg_s);
  v.field({"event_noise_px", "px", "event pixel noise per axis", atLeast(0)}, o.event_noise_px);
  v.field({"omega_error_deg_s", "deg/s", "error of the given angular velocity", atLeast(0)}, o.omega_error_deg_s);
  v.field({"outlier_fraction", "-", "share of events replaced by uniform pixels", withinBelow(0, 1)},
          o.outlier_fraction);
  v.field({"acceleration", "m/s^2", "|a| of a constant acceleration", atLeast(0)}, o.acceleration);
  v.field({"min_separation_px", "px", "endpoint distance at t_ref", atLeast(0)}, o.min_separation_px);
  v.field({"depth_range", "m", "endpoint depths", above(0)}, o.depth_range);
  v.field({"max_attempts", "", "segment draws per line", atLeast(1)}, o.max_attempts);
  v.field({"max_motion_draws", "", "motion draws before giving up", atLeast(1)}, o.max_motion_draws);
  v.field({"integer_pixels", "", "event pixels rounded to integers"}, o.integer_pixels);
}

std::string PeerSceneOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (!(depth_range[1] >= depth_range[0])) e += "depth_range: must be min <= max; ";
  return e + camera.validate() + line_fit.validate();
}

namespace {
Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (;;) {
    const Vec3 u(n(rng), n(rng), n(rng));
    if (u.norm() > 1e-9) return u.normalized();
  }
}
}  // namespace

PeerSceneTrial generatePeerScene(const PeerSceneOptions& o, std::mt19937_64& rng) {
  PeerSceneTrial trial;
  if (const std::string err = o.validate(); !err.empty()) {
    trial.message = "peer scene options: " + err;
    return trial;
  }
  const double deg = M_PI / 180.0;
  const double t0 = o.t_ref - 0.5 * o.duration, t1 = o.t_ref + 0.5 * o.duration;
  std::uniform_real_distribution<double> u01(0.0, 1.0), uz(o.depth_range[0], o.depth_range[1]);
  std::normal_distribution<double> noise(0.0, o.event_noise_px);

  const CameraModel& cam = o.camera;
  auto inCamera = [](const Mat3& R, const Vec3& p, const Vec3& X) { return Vec3(R.transpose() * (X - p)); };
  auto visible = [&](const Vec3& Xc) { return Xc.z() > 1e-6 && cam.inImage(cam.project(Xc)); };
  const int n_lines = o.n_lines;

  // Motion (constant rate, velocity constant in the reference frame) and the
  // segments; the motion is drawn again when a line finds no segment.
  Vec3 v = Vec3::Zero(), a = Vec3::Zero();
  // The camera's position in the reference frame at time t.
  auto position = [&](double t) {
    const double tau = t - o.t_ref;
    return Vec3(trial.true_motion.positionMatrix(t) * v + 0.5 * tau * tau * a);
  };
  Mat3 R0 = Mat3::Identity(), R1 = Mat3::Identity();
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();
  std::vector<std::array<Vec3, 2>> segments;
  for (int draw = 0; draw < o.max_motion_draws && static_cast<int>(segments.size()) < n_lines; ++draw) {
    segments.clear();
    trial.true_omega = randomUnit(rng) * (o.omega_deg_s * deg);
    trial.true_direction = randomUnit(rng);
    v = trial.true_direction * o.speed;
    // Drawn only when asked for, so that the other studies' draws stay the same.
    if (o.acceleration > 0.0) a = randomUnit(rng) * o.acceleration;
    trial.true_acceleration = a;
    trial.true_motion =
        MotionModel::gyroIntegrated({t0, t1}, {trial.true_omega, trial.true_omega}, o.t_ref,
                                    VelocityFrame::Reference);
    R0 = trial.true_motion.rotation(t0);
    R1 = trial.true_motion.rotation(t1);
    p0 = position(t0);
    p1 = position(t1);
    for (int i = 0; i < n_lines; ++i) {
      bool found = false;
      for (int attempt = 0; attempt < o.max_attempts && !found; ++attempt) {
        const Vec2 a(cam.width * u01(rng), cam.height * u01(rng));
        const Vec2 b(cam.width * u01(rng), cam.height * u01(rng));
        const double za = uz(rng), zb = uz(rng);
        if ((a - b).norm() < o.min_separation_px) continue;
        const std::array<Vec3, 2> seg{cam.bearing(a) * za, cam.bearing(b) * zb};
        found = visible(inCamera(R0, p0, seg[0])) && visible(inCamera(R0, p0, seg[1])) &&
                visible(inCamera(R1, p1, seg[0])) && visible(inCamera(R1, p1, seg[1]));
        if (found) segments.push_back(seg);
      }
      if (!found) break;
    }
  }
  if (static_cast<int>(segments.size()) < n_lines) {
    trial.message = "no motion kept the segments within the image at both ends of the window after " +
                    std::to_string(o.max_motion_draws) + " draws";
    return trial;
  }
  const Vec3 gyro_error = randomUnit(rng) * (o.omega_error_deg_s * deg);
  trial.given_motion = trial.true_motion.withOmegaOffset(gyro_error);

  trial.observations.focal_px = trial.truth.focal_px = cam.focal();
  trial.observations.clusters.resize(static_cast<size_t>(n_lines));
  trial.truth.clusters.resize(static_cast<size_t>(n_lines));
  for (int i = 0; i < n_lines; ++i) {
    const std::array<Vec3, 2>& seg = segments[static_cast<size_t>(i)];
    trial.segments.push_back(seg);

    // Events, sorted by time (the line fit needs ascending times).
    struct Raw {
      double t;
      Vec3 f_true;
      Vec3 f;
      bool inlier;
    };
    std::vector<Raw> raw;
    raw.reserve(static_cast<size_t>(o.events_per_line));
    for (int k = 0; k < o.events_per_line; ++k) {
      const double t = t0 + o.duration * u01(rng);
      if (u01(rng) < o.outlier_fraction) {
        const Vec2 px(cam.width * u01(rng), cam.height * u01(rng));
        raw.push_back({t, Vec3::Zero(), cam.bearing(px), false});
        continue;
      }
      const double s = u01(rng);
      const Mat3 R = trial.true_motion.rotation(t);
      const Vec3 Xc = inCamera(R, position(t), seg[0] + s * (seg[1] - seg[0]));
      const Vec2 px = cam.project(Xc);
      Vec2 noisy = px + Vec2(noise(rng), noise(rng));
      if (o.integer_pixels) noisy = noisy.array().round().matrix();
      raw.push_back({t, cam.bearing(px), cam.bearing(noisy), true});
    }
    std::sort(raw.begin(), raw.end(), [](const Raw& x, const Raw& y) { return x.t < y.t; });
    auto& c = trial.observations.clusters[static_cast<size_t>(i)];
    auto& ct = trial.truth.clusters[static_cast<size_t>(i)];
    c.id = ct.id = i;
    for (const Raw& r : raw) {
      c.times.push_back(r.t);
      c.bearings.push_back(r.f);
      if (!r.inlier) continue;
      ct.times.push_back(r.t);
      ct.bearings.push_back(r.f_true);
    }
    // Truth lines: the plane normals of the segment seen at t0 and t1.
    auto trueLine = [&](const Mat3& R, const Vec3& p, double t) {
      const Vec3 a = inCamera(R, p, seg[0]), b = inCamera(R, p, seg[1]);
      return TimedLine{a.cross(b).normalized(), t};
    };
    ct.l1 = trueLine(R0, p0, t0);
    ct.l3 = trueLine(R1, p1, t1);
    ct.has_l2 = false;
    if (attachFittedLines(c, trial.observations.focal_px, o.line_fit, &trial.given_motion))
      ++trial.lines_fitted;
  }
  trial.ok = true;
  return trial;
}

}  // namespace celc
