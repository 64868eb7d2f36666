#include "celc/cluster/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "celc/geometry/motion_model.hpp"

namespace celc {
namespace {

struct Pose {
  Mat3 R;
  Vec3 p;
};

Pose poseAt(const MotionModel& m, const Vec3& v, double t) {
  return {m.rotation(t), m.positionMatrix(t) * v};
}

Vec3 toCamera(const Pose& pose, const Vec3& x_ref) { return pose.R.transpose() * (x_ref - pose.p); }

double pointSegmentDistance(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0.0 ? std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (q - (a + s * ab)).norm();
}

}  // namespace

Vec3 LabelledWindow::lineNormal(int line, double t) const {
  const MotionModel m = MotionModel::constantTwist(omega, 0.0);
  const Pose pose = poseAt(m, v, t);
  return toCamera(pose, p1[line]).cross(toCamera(pose, p2[line])).normalized();
}

LabelledWindow generateLabelledWindow(const LabelledWindowOptions& o) {
  LabelledWindow w;
  w.camera = o.camera;
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  auto randomUnit = [&] {
    Vec3 d(N(rng), N(rng), N(rng));
    return d.norm() > 1e-9 ? Vec3(d.normalized()) : Vec3(Vec3::UnitX());
  };
  w.v = o.speed_m_per_s * randomUnit();
  w.omega = o.omega_rad_per_s * randomUnit();
  const MotionModel model = MotionModel::constantTwist(w.omega, 0.0);
  const CameraModel& cam = o.camera;
  const double T = o.duration_s;
  const Pose pose0 = poseAt(model, w.v, 0.0), pose1 = poseAt(model, w.v, T);

  auto project = [&](const Pose& pose, const Vec3& x, Vec2* px) {
    const Vec3 c = toCamera(pose, x);
    if (c.z() < 0.1) return false;
    *px = cam.project(c);
    return true;
  };
  std::vector<double> weights;
  std::vector<bool> polarity;
  const double margin = 20.0;
  for (int line = 0; line < o.n_lines; ++line) {
    for (int attempt = 0; attempt < 500; ++attempt) {
      const Vec2 m(margin + U(rng) * (cam.width - 2 * margin),
                   margin + U(rng) * (cam.height - 2 * margin));
      const double th = U(rng) * M_PI;
      const double len = o.min_length_px + U(rng) * (o.max_length_px - o.min_length_px);
      const double depth = o.depth_min_m + U(rng) * (o.depth_max_m - o.depth_min_m);
      const Vec2 d(std::cos(th), std::sin(th));
      auto backproject = [&](const Vec2& px, double z) {
        const Vec3 b = cam.bearing(px);
        return Vec3(b * z);
      };
      const Vec3 a = backproject(m - 0.5 * len * d, depth * (1.0 + 0.3 * (U(rng) - 0.5)));
      const Vec3 b = backproject(m + 0.5 * len * d, depth * (1.0 + 0.3 * (U(rng) - 0.5)));
      Vec2 a0 = Vec2::Zero(), b0 = a0, a1 = a0, b1 = a0;
      if (!project(pose0, a, &a0) || !project(pose0, b, &b0) || !project(pose1, a, &a1) ||
          !project(pose1, b, &b1))
        continue;
      const Vec2 m0 = 0.5 * (a0 + b0), m1 = 0.5 * (a1 + b1);
      if (!cam.inImage(m0) || !cam.inImage(m1)) continue;
      bool too_close = false;
      for (int k = 0; k < w.n_lines() && !too_close; ++k) {
        Vec2 ka0 = Vec2::Zero(), kb0 = ka0, ka1 = ka0, kb1 = ka0;
        project(pose0, w.p1[k], &ka0), project(pose0, w.p2[k], &kb0);
        project(pose1, w.p1[k], &ka1), project(pose1, w.p2[k], &kb1);
        const double dmin = std::min({pointSegmentDistance(m0, ka0, kb0),
                                      pointSegmentDistance(m1, ka1, kb1),
                                      pointSegmentDistance(0.5 * (ka0 + kb0), a0, b0),
                                      pointSegmentDistance(0.5 * (ka1 + kb1), a1, b1)});
        too_close = dmin < o.min_separation_px;
      }
      if (too_close) continue;
      const Vec2 dir = (b0 - a0).normalized();
      const double travel = std::fabs(Vec2(-dir.y(), dir.x()).dot(m1 - m0));
      w.p1.push_back(a);
      w.p2.push_back(b);
      weights.push_back((b0 - a0).norm() * std::max(travel, 1.0));
      polarity.push_back(U(rng) < 0.5);
      break;
    }
  }
  const int n_noise = static_cast<int>(std::lround(o.noise_fraction * o.n_events));
  const int n_line_events = o.n_events - n_noise;
  const double wsum = std::accumulate(weights.begin(), weights.end(), 0.0);
  std::vector<Event> ev;
  std::vector<int> lab;
  ev.reserve(o.n_events);
  lab.reserve(o.n_events);
  for (int k = 0; k < w.n_lines(); ++k) {
    const int count = static_cast<int>(std::floor(n_line_events * weights[k] / wsum));
    for (int i = 0; i < count; ++i) {
      for (int attempt = 0; attempt < 20; ++attempt) {
        const double t = U(rng) * T;
        const double s = U(rng);
        Vec2 px = Vec2::Zero();
        if (!project(poseAt(model, w.v, t), w.p1[k] + s * (w.p2[k] - w.p1[k]), &px)) continue;
        px += o.pixel_noise_px * Vec2(N(rng), N(rng));
        px = Vec2(std::round(px.x()), std::round(px.y()));
        if (!cam.inImage(px)) continue;
        ev.push_back({t, static_cast<float>(px.x()), static_cast<float>(px.y()), polarity[k]});
        lab.push_back(k);
        break;
      }
    }
  }
  for (int i = 0; i < n_noise; ++i) {
    const float x = static_cast<float>(std::min<double>(cam.width - 1, std::floor(U(rng) * cam.width)));
    const float y = static_cast<float>(std::min<double>(cam.height - 1, std::floor(U(rng) * cam.height)));
    ev.push_back({U(rng) * T, x, y, U(rng) < 0.5});
    lab.push_back(-1);
  }
  std::vector<size_t> order(ev.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return ev[a].t < ev[b].t; });
  w.events.reserve(ev.size());
  w.labels.reserve(ev.size());
  for (size_t i : order) {
    w.events.push_back(ev[i]);
    w.labels.push_back(lab[i]);
  }
  return w;
}

}  // namespace celc
