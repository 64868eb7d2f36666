#include "celc/sim/line_scene.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace celc {

std::string LineSceneOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (!(x_range[1] >= x_range[0] && y_range[1] >= y_range[0] && z_range[1] >= z_range[0]))
    e += "x_range, y_range, z_range: each must be [min, max]; ";
  if (!(z_range[0] > 0.0)) e += "z_range: must lie in front of the camera (> 0); ";
  return e + inSection("camera", camera.validate());
}

namespace {
Vec3 gaussian3(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}
}  // namespace

LineSceneTrial generateLineScene(const LineSceneOptions& o, std::mt19937_64& rng) {
  LineSceneTrial trial;
  std::uniform_real_distribution<double> ux(o.x_range[0], o.x_range[1]),
      uy(o.y_range[0], o.y_range[1]), uz(o.z_range[0], o.z_range[1]), u01(0.0, 1.0);
  std::normal_distribution<double> ev_noise(0.0, o.event_noise_px), ln_noise(0.0, o.line_noise_px);
  const double ts = 0.0, te = o.duration, tm = 0.5 * (ts + te);

  // Motion: the truth and what the gyroscope tells the solvers.
  const Vec3 gyro_error = gaussian3(rng, o.omega_noise);
  if (o.motion == MotionModelKind::ConstantTwist) {
    trial.true_motion = MotionModel::constantTwist(o.omega, ts);
    trial.given_motion = MotionModel::constantTwist(o.omega + gyro_error, ts);
  } else {
    std::vector<double> times;
    std::vector<Vec3> rates;
    const int n = std::max(2, static_cast<int>(std::ceil(o.duration * o.gyro_rate_hz)) + 1);
    for (int i = 0; i < n; ++i) {
      const double t = ts + o.duration * i / (n - 1);
      times.push_back(t);
      rates.push_back(o.omega + o.omega_wobble * std::sin(2.0 * M_PI * t / o.duration));
    }
    trial.true_motion = MotionModel::gyroIntegrated(times, rates, ts);
    trial.given_motion = trial.true_motion.withOmegaOffset(gyro_error);
  }
  const double speed = o.velocity.norm();
  trial.true_direction = speed > 0.0 ? Vec3(o.velocity / speed) : Vec3::Zero();

  const CameraModel& cam = o.camera;
  Vec3& a = trial.true_acceleration;
  auto inCamera = [&](const Vec3& X, double t) {
    const Mat3 R = trial.true_motion.rotation(t);
    const Vec3 p = trial.true_motion.positionMatrix(t) * o.velocity + 0.5 * (t - ts) * (t - ts) * a;
    return Vec3(R.transpose() * (X - p));
  };
  auto pixelAt = [&](const Vec3& X, double t) { return cam.project(inCamera(X, t)); };
  auto bearingOf = [&](const Vec2& px) { return cam.bearing(px); };
  auto noisyLine = [&](const std::array<Vec3, 2>& seg, double t) {
    const Vec2 a = pixelAt(seg[0], t) + Vec2(ln_noise(rng), ln_noise(rng));
    const Vec2 b = pixelAt(seg[1], t) + Vec2(ln_noise(rng), ln_noise(rng));
    return TimedLine{bearingOf(a).cross(bearingOf(b)).normalized(), t};
  };

  auto& obs = trial.observations;
  obs.focal_px = cam.focal();
  const int n_lines = o.fixed_segments.empty() ? o.n_lines : static_cast<int>(o.fixed_segments.size());
  obs.clusters.resize(static_cast<size_t>(n_lines));
  auto fitLines = [&](int i) {
    const std::array<Vec3, 2>& seg = trial.segments[static_cast<size_t>(i)];
    auto& c = obs.clusters[static_cast<size_t>(i)];
    c.id = i;
    c.l1 = noisyLine(seg, ts);
    c.l2 = noisyLine(seg, tm);
    c.l3 = noisyLine(seg, te);
    c.has_l2 = true;
  };
  // Each segment, then its lines (without an acceleration, in turn: the
  // draws of the paper's scene).
  for (int i = 0; i < n_lines; ++i) {
    std::array<Vec3, 2> seg = o.fixed_segments.empty()
                                  ? std::array<Vec3, 2>{Vec3(ux(rng), uy(rng), uz(rng)),
                                                        Vec3(ux(rng), uy(rng), uz(rng))}
                                  : o.fixed_segments[static_cast<size_t>(i)];
    trial.segments.push_back(seg);
    if (!(o.acceleration > 0.0)) fitLines(i);
  }
  if (o.acceleration > 0.0) {
    // The acceleration's direction, drawn again while it brings the camera
    // within kMinDepth of a segment's endpoint; then the lines.
    constexpr double kMinDepth = 0.5;  // [m]
    std::normal_distribution<double> n01(0.0, 1.0);
    for (int draw = 0; draw < 100; ++draw) {
      Vec3 d(n01(rng), n01(rng), n01(rng));
      if (!(d.norm() > 1e-9)) continue;
      a = d.normalized() * o.acceleration;
      bool front = true;
      for (int k = 0; k <= 10 && front; ++k)
        for (const auto& seg : trial.segments)
          for (const Vec3& X : seg) front = front && inCamera(X, ts + (te - ts) * k / 10.0).z() >= kMinDepth;
      if (front) break;
    }
    for (int i = 0; i < n_lines; ++i) fitLines(i);
  }
  // Side of each line's edge offset (drawn only when there is one, so that
  // the other draws do not depend on it).
  std::vector<double> offset(static_cast<size_t>(n_lines), 0.0);
  if (o.edge_offset_px > 0.0)
    for (double& d : offset) d = u01(rng) < 0.5 ? -o.edge_offset_px : o.edge_offset_px;
  // Events: a random line, a random time, a random point on the segment.
  const int n_events = n_lines * o.events_per_line;
  struct Raw {
    double t;
    Vec2 px;
    int label;
  };
  std::vector<Raw> raw;
  raw.reserve(static_cast<size_t>(n_events));
  for (int e = 0; e < n_events; ++e) {
    const double t = ts + (te - ts) * u01(rng);
    if (u01(rng) < o.outlier_fraction) {
      raw.push_back({t, Vec2(cam.width * u01(rng), cam.height * u01(rng)), -1});
      continue;
    }
    const int line = static_cast<int>(u01(rng) * n_lines) % n_lines;
    const auto& seg = trial.segments[static_cast<size_t>(line)];
    const double s = u01(rng);
    Vec2 px = pixelAt(seg[0] + s * (seg[1] - seg[0]), t) + Vec2(ev_noise(rng), ev_noise(rng));
    if (offset[static_cast<size_t>(line)] != 0.0) {
      const Vec2 along = pixelAt(seg[1], t) - pixelAt(seg[0], t);
      if (along.norm() > 0.0)
        px += offset[static_cast<size_t>(line)] * Vec2(-along.y(), along.x()).normalized();
    }
    raw.push_back({t, px, line});
  }
  std::sort(raw.begin(), raw.end(), [](const Raw& a, const Raw& b) { return a.t < b.t; });
  for (const Raw& r : raw) {
    trial.pixel_events.push_back(
        Event{r.t, static_cast<float>(r.px.x()), static_cast<float>(r.px.y()), true});
    trial.labels.push_back(r.label);
    // Outliers join a random cluster: the solvers must cope with them.
    const int c = r.label >= 0 ? r.label : static_cast<int>(u01(rng) * n_lines) % n_lines;
    auto& cl = obs.clusters[static_cast<size_t>(c)];
    cl.times.push_back(r.t);
    cl.bearings.push_back(bearingOf(r.px));
  }
  return trial;
}

}  // namespace celc
