// Tests of the rendering event simulator (celc synth): scene shading, the
// per-pixel event model, refractory period, ordering, IMU, trajectories,
// labels, SCENE.yaml parsing and the written sequence directory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "celc/geometry/motion_model.hpp"
#include "celc/geometry/so3.hpp"
#include "celc/sim/render.hpp"
#include "celc/sim/render_sequence.hpp"
#include "celc/sim/scene.hpp"
#include "celc/sim/scene_trajectory.hpp"

using namespace celc;
using namespace celc;
namespace fs = std::filesystem;

namespace {

CameraModel smallCamera() {
  CameraModel c;
  c.width = 64;
  c.height = 48;
  c.fx = c.fy = 60.0;
  c.cx = 31.5;
  c.cy = 23.5;
  return c;
}

PlaneSpec chessSpec(double depth) {
  PlaneSpec p;
  p.texture = TextureKind::Chessboard;
  p.position = Vec3(0.0, 0.0, depth);
  p.rotation = Vec3(0.1, -0.2, 0.05);
  p.square = 0.1;
  p.columns = 40;
  p.rows = 30;
  p.dark = 0.2;
  p.light = 0.8;
  return p;
}

TrajectorySpec twistSpec(const Vec3& v, const Vec3& w) {
  TrajectorySpec t;
  t.kind = TrajectoryKind::ConstantTwist;
  t.v = v;
  t.w = w;
  return t;
}

RenderOptions quietOptions() {
  RenderOptions o;
  o.refractory = 0.0;
  o.noise_rate = 0.0;
  o.threads = 2;
  o.seed = 7;
  return o;
}

std::vector<SimEvent> simulate(const Scene& scene, const CameraModel& cam, const Trajectory& tr,
                               const RenderOptions& o, double t_end) {
  RenderEventSimulator sim(scene, cam, tr, o);
  std::vector<SimEvent> ev;
  sim.advanceTo(t_end, ev);
  return ev;
}

fs::path tempDir(const std::string& name) {
  // Per process: CTest runs tests in parallel, and several builds may share /tmp.
  const fs::path d =
      fs::temp_directory_path() / ("celc_sim_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
  return (a + s * ab - p).norm();
}

}  // namespace

// A fronto-parallel chessboard whose lines fall half-way between pixel centres:
// with a 1 px ramp every pixel sees exactly its square's intensity.
TEST(SimScene, ChessboardPixelsSeeTheirSquare) {
  CameraModel cam = smallCamera();  // f = 60 px; squares of 0.1 m at 1 m are 6 px
  PlaneSpec p = chessSpec(1.0);
  p.rotation = Vec3::Zero();
  p.columns = 20;
  p.rows = 16;  // 2 m x 1.6 m: covers the image (1.07 m x 0.8 m at 1 m)
  const Scene scene = Scene::build({p}, 0.5, 1);
  RigidPose T;  // camera at the origin looking along +z
  const auto L = renderLogImage(scene, cam, T, 0.01, 1.0);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      // Plane coordinate u = (x - cx) / f * 1 m; the board starts at u = -1 m.
      // Lines at u = -1 + 0.1 k m, i.e. x = cx + 6 (k - 10) px = 31.5 + 6 m': half-integers.
      const double u = (x - cam.cx) / cam.fx + 1.0, v = (y - cam.cy) / cam.fy + 0.8;
      const int i = static_cast<int>(std::floor(u / 0.1)),
                j = static_cast<int>(std::floor(v / 0.1));
      const double expected = ((i + j) % 2 == 0) ? 0.8 : 0.2;
      ASSERT_NEAR(std::exp(L[y * cam.width + x]) - 0.01, expected, 1e-5) << x << "," << y;
    }
  // A 3 px ramp blends pixels next to a line: the two pixels around x = 31.5
  // (0.5 px away from it) get 1/3 of the step from their own side.
  const auto L3 = renderLogImage(scene, cam, T, 0.01, 3.0);
  const double I31 = std::exp(L3[10 * cam.width + 31]) - 0.01;
  const double I32 = std::exp(L3[10 * cam.width + 32]) - 0.01;
  EXPECT_NEAR(std::abs(I31 - I32), 0.6 / 3.0, 1e-4);
  EXPECT_NEAR(I31 + I32, 1.0, 1e-4);
}

TEST(SimScene, EdgesHaveUniqueIdsOnTheirPlanes) {
  PlaneSpec rect;
  rect.texture = TextureKind::Rectangles;
  rect.position = Vec3(0.3, 0.0, 3.0);
  rect.count = 25;
  const Scene scene = Scene::build({chessSpec(2.0), rect}, 0.5, 3);
  const auto edges = scene.edges();
  ASSERT_EQ(static_cast<int>(edges.size()), scene.edgeCount());
  EXPECT_EQ(scene.edgeCount(), (40 + 1) + (30 + 1) + 4 + 4 * 25);
  std::set<int> ids;
  for (const auto& e : edges) {
    ids.insert(e.id);
    // Both end points lie on the plane of the edge.
    const ScenePlane& pl = scene.planes[e.id < scene.planes[1].edge_id_offset ? 0 : 1];
    const Vec3 n = pl.T_world_plane.R.col(2);
    EXPECT_NEAR(n.dot(e.p0 - pl.T_world_plane.p), 0.0, 1e-9);
    EXPECT_NEAR(n.dot(e.p1 - pl.T_world_plane.p), 0.0, 1e-9);
  }
  EXPECT_EQ(ids.size(), edges.size());
  EXPECT_EQ(*ids.begin(), 0);
  EXPECT_EQ(*ids.rbegin(), scene.edgeCount() - 1);
}

// Threshold model: after every render, for every pixel,
//   L(t) - L(0) - (n_on C+_i - n_off C-_i)  lies in (-C-_i, C+_i),
// with L(t) rendered independently of the simulator's state.
TEST(SimRender, PixelEventsMatchLogIntensityChange) {
  const CameraModel cam = smallCamera();
  const Scene scene = Scene::build({chessSpec(1.0)}, 0.5, 1);
  const Trajectory tr(twistSpec(Vec3(0.8, 0.3, 0.2), Vec3(0.2, -0.3, 0.4)), 1.0);
  const RenderOptions o = quietOptions();
  RenderEventSimulator sim(scene, cam, tr, o);
  const auto L0 = renderLogImage(scene, cam, tr.pose(0.0), o.log_eps, o.smoothing_px);
  std::vector<SimEvent> ev;
  std::vector<double> sum(L0.size(), 0.0);
  std::vector<int> count(L0.size(), 0);
  size_t used = 0;
  int busy_pixels = 0;
  for (double t : {0.03, 0.1, 0.2}) {
    sim.advanceTo(t, ev);
    for (; used < ev.size(); ++used) {
      const size_t i = static_cast<size_t>(ev[used].y) * cam.width + ev[used].x;
      sum[i] += ev[used].on ? sim.thresholdOn()[i] : -sim.thresholdOff()[i];
      ++count[i];
    }
    const auto L = renderLogImage(scene, cam, tr.pose(t), o.log_eps, o.smoothing_px);
    busy_pixels = 0;
    for (size_t i = 0; i < L.size(); ++i) {
      const double residual = (double(L[i]) - L0[i]) - sum[i];
      // float state: 1e-4 of slack in log units.
      ASSERT_GT(residual, -sim.thresholdOff()[i] - 1e-4) << "pixel " << i << " t " << t;
      ASSERT_LT(residual, sim.thresholdOn()[i] + 1e-4) << "pixel " << i << " t " << t;
      busy_pixels += count[i] > 0;
    }
  }
  EXPECT_EQ(sim.stats().events_on + sim.stats().events_off, static_cast<int64_t>(ev.size()));
  // The board moves ~20 px: most pixels see edges pass.
  EXPECT_GT(busy_pixels, static_cast<int>(L0.size() / 2));
  EXPECT_GT(ev.size(), 5000u);
}

// Within one render step an ON crossing cannot follow an OFF one (L is linear
// between renders), and events of one pixel have increasing times.
TEST(SimRender, PolarityRunsFollowMonotoneSegments) {
  const CameraModel cam = smallCamera();
  const Scene scene = Scene::build({chessSpec(1.0)}, 0.5, 1);
  const Trajectory tr(twistSpec(Vec3(1.0, 0.0, 0.0), Vec3::Zero()), 1.0);
  const auto ev = simulate(scene, cam, tr, quietOptions(), 0.1);
  std::map<int, std::vector<SimEvent>> per;
  for (const auto& e : ev) per[e.y * cam.width + e.x].push_back(e);
  // Pure sideways translation in front of a fronto-tilted board: a pixel sees
  // dark->light->dark...; every polarity run is at most ceil(|log ratio| / Cmin) long.
  const double max_run = std::ceil(std::log((0.01 + 0.8) / (0.01 + 0.2)) / (0.25 - 4 * 0.03)) + 1;
  for (const auto& [i, v] : per) {
    int run = 1;
    for (size_t k = 1; k < v.size(); ++k) {
      ASSERT_GE(v[k].t_us, v[k - 1].t_us);
      run = v[k].on == v[k - 1].on ? run + 1 : 1;
      ASSERT_LE(run, max_run) << "pixel " << i;
    }
  }
}

TEST(SimRender, RefractoryPeriodIsRespected) {
  const CameraModel cam = smallCamera();
  const Scene scene = Scene::build({chessSpec(1.0)}, 0.5, 1);
  const Trajectory tr(twistSpec(Vec3(1.5, 0.5, 0.0), Vec3(0.0, 0.0, 0.5)), 1.0);
  RenderOptions o = quietOptions();
  o.refractory = 2e-3;
  o.noise_rate = 20.0;
  RenderEventSimulator sim(scene, cam, tr, o);
  std::vector<SimEvent> ev;
  sim.advanceTo(0.15, ev);
  std::map<int, int64_t> last;
  for (const auto& e : ev) {
    const int i = e.y * cam.width + e.x;
    const auto it = last.find(i);
    if (it != last.end()) {
      ASSERT_GE(e.t_us - it->second, 2000) << "pixel " << i;
    }
    last[i] = e.t_us;
  }
  EXPECT_GT(sim.stats().refractory_dropped, 100);  // the limit was actually exercised
  EXPECT_GT(sim.stats().events_noise, 0);
}

TEST(SimRender, TimestampsSortedRoundedAndIndependentOfThreads) {
  const CameraModel cam = smallCamera();
  PlaneSpec seg;
  seg.texture = TextureKind::Segments;
  seg.position = Vec3(0.0, 0.0, 1.5);
  seg.width = 3.0;
  seg.height = 2.0;
  seg.count = 60;
  const Scene scene = Scene::build({seg, chessSpec(3.0)}, 0.4, 5);
  const Trajectory tr(twistSpec(Vec3(0.6, -0.4, 0.3), Vec3(0.3, 0.2, -0.2)), 1.0);
  RenderOptions o = quietOptions();
  o.noise_rate = 5.0;
  o.refractory = 5e-4;
  o.threads = 1;
  const auto e1 = simulate(scene, cam, tr, o, 0.12);
  o.threads = 3;
  const auto e3 = simulate(scene, cam, tr, o, 0.12);
  ASSERT_EQ(e1.size(), e3.size());
  ASSERT_GT(e1.size(), 1000u);
  for (size_t k = 0; k < e1.size(); ++k) {
    ASSERT_EQ(e1[k].t_us, e3[k].t_us);
    ASSERT_EQ(e1[k].x, e3[k].x);
    ASSERT_EQ(e1[k].y, e3[k].y);
    ASSERT_EQ(e1[k].on, e3[k].on);
    ASSERT_EQ(e1[k].label, e3[k].label);
  }
  for (size_t k = 1; k < e1.size(); ++k) ASSERT_LE(e1[k - 1].t_us, e1[k].t_us);
  EXPECT_GT(e1.front().t_us, 0);
  EXPECT_LE(e1.back().t_us, 120000);
}

// Skipping pixels far from edges must not change a single event (it checks the
// free-distance bound of every texture kind, including occlusion between planes).
TEST(SimRender, SkippingStaticPixelsChangesNothing) {
  const CameraModel cam = smallCamera();
  PlaneSpec rect;
  rect.texture = TextureKind::Rectangles;
  rect.position = Vec3(0.2, 0.1, 1.2);
  rect.width = 1.0;
  rect.height = 0.8;
  rect.count = 12;
  rect.size_range = Vec2(0.1, 0.4);
  rect.random_angle = true;
  const Scene two = Scene::build({rect, chessSpec(2.0)}, 0.5, 9);
  const Scene one = Scene::build({chessSpec(1.5)}, 0.5, 9);
  TrajectorySpec constant = twistSpec(Vec3(0.7, 0.2, 0.4), Vec3(0.1, 0.3, 0.2));
  TrajectorySpec sinus = constant;
  sinus.kind = TrajectoryKind::Sinusoid;
  sinus.amplitude_v = Vec3(0.6, 0.5, 0.0);
  sinus.amplitude_w = Vec3(0.0, 0.3, 0.4);
  sinus.frequency = 4.0;
  TrajectorySpec piecewise;  // slow, then a sudden fast motion
  piecewise.kind = TrajectoryKind::Piecewise;
  piecewise.segments = {{0.05, Vec3(0.05, 0.0, 0.0), Vec3::Zero()},
                        {0.1, Vec3(1.5, -0.5, 0.2), Vec3(0.0, 0.5, 0.0)}};
  for (const Scene* scene : {&one, &two})
    for (const TrajectorySpec& spec : {constant, sinus, piecewise}) {
      const Trajectory tr(spec, 1.0);
      RenderOptions o = quietOptions();
      o.skip_static = false;
      RenderEventSimulator full(*scene, cam, tr, o);
      o.skip_static = true;
      RenderEventSimulator fast(*scene, cam, tr, o);
      std::vector<SimEvent> a, b;
      full.advanceTo(0.15, a);
      fast.advanceTo(0.15, b);
      const std::string what = toString(spec.kind) + (scene == &one ? " 1 plane" : " 2 planes");
      ASSERT_EQ(a.size(), b.size()) << what;
      ASSERT_GT(a.size(), 1000u) << what;
      for (size_t k = 0; k < a.size(); ++k) {
        ASSERT_EQ(a[k].t_us, b[k].t_us) << what;
        ASSERT_EQ(a[k].x, b[k].x) << what;
        ASSERT_EQ(a[k].y, b[k].y) << what;
        ASSERT_EQ(a[k].on, b[k].on) << what;
      }
      EXPECT_LT(fast.stats().pixels_shaded, full.stats().pixels_shaded) << what;
    }
}

TEST(SimRender, AdaptiveStepBoundsImageMotion) {
  const CameraModel cam = smallCamera();
  const Scene scene = Scene::build({chessSpec(1.0)}, 0.5, 1);
  const Trajectory tr(twistSpec(Vec3(2.0, 0.0, 0.0), Vec3::Zero()), 1.0);
  RenderOptions o = quietOptions();
  RenderEventSimulator sim(scene, cam, tr, o);
  // ~2 m/s at ~1 m with f = 60 px: about 120 px/s (the board is tilted).
  const double speed = sim.imageSpeed(0.0);
  EXPECT_GT(speed, 90.0);
  EXPECT_LT(speed, 170.0);
  std::vector<SimEvent> ev;
  sim.advanceTo(0.05, ev);
  EXPECT_LE(sim.stats().max_step * speed, 0.3 + 1e-9);
  EXPECT_GE(sim.stats().renders, static_cast<int64_t>(0.05 * speed / 0.3));
}

TEST(SimRender, LabelsNameANearbyEdgeAndNoiseIsMinusOne) {
  const CameraModel cam = smallCamera();
  PlaneSpec rect;
  rect.texture = TextureKind::Rectangles;
  rect.position = Vec3(0.0, 0.0, 1.0);
  rect.width = 2.0;
  rect.height = 1.6;
  rect.count = 30;
  rect.size_range = Vec2(0.1, 0.4);
  rect.random_angle = true;
  const Scene chess = Scene::build({chessSpec(1.0)}, 0.5, 1);
  const Scene rects = Scene::build({rect}, 0.5, 4);
  const Trajectory tr(twistSpec(Vec3(0.8, 0.3, 0.2), Vec3(0.2, -0.3, 0.4)), 1.0);
  for (const Scene* scene : {&chess, &rects}) {
    RenderOptions o = quietOptions();
    o.noise_rate = 10.0;
    RenderEventSimulator sim(*scene, cam, tr, o);
    std::vector<SimEvent> ev;
    sim.advanceTo(0.1, ev);
    const auto edges = scene->edges();
    int64_t noise = 0, far = 0, signal = 0;
    for (const auto& e : ev) {
      if (e.label < 0) {
        ++noise;
        continue;
      }
      ++signal;
      ASSERT_LT(e.label, scene->edgeCount());
      const RigidPose T = tr.pose(e.t_us * 1e-6);
      const SceneEdge& s = edges[e.label];
      const Vec2 a = cam.project(T.R.transpose() * (s.p0 - T.p));
      const Vec2 b = cam.project(T.R.transpose() * (s.p1 - T.p));
      // The intensity of a pixel changes while an edge is within 0.5 px (1 px
      // ramp); the label is taken at the render after the event (<= 0.3 px later).
      if (pointSegmentDistance(Vec2(e.x, e.y), a, b) > 1.0) ++far;
    }
    EXPECT_EQ(noise, sim.stats().events_noise);
    EXPECT_GT(noise, 0);
    EXPECT_GT(signal, 1000);
    EXPECT_EQ(far, 0) << (scene == &chess ? "chessboard" : "rectangles");
  }
}

TEST(SimTrajectory, ConstantTwistMatchesMotionModel) {
  TrajectorySpec s = twistSpec(Vec3(0.5, -0.2, 1.0), Vec3(0.3, 0.1, -0.4));
  s.initial = {so3::exp(Vec3(0.2, 0.4, -0.1)), Vec3(1.0, 2.0, 3.0)};
  const Trajectory tr(s, 1.0);
  const double t_ref = 0.3;
  const MotionModel mm = MotionModel::constantTwist(s.w, t_ref);
  for (double t : {0.0, 0.25, 0.31, 0.8}) {
    const RigidPose rel = tr.pose(t_ref).inverse() * tr.pose(t);
    EXPECT_LT((rel.R - mm.rotation(t)).norm(), 1e-12);
    EXPECT_LT((rel.p - mm.positionMatrix(t) * s.v).norm(), 1e-12);
  }
}

// The ground-truth velocity a consumer computes from the pose file equals the twist.
TEST(SimTrajectory, PoseDerivativesEqualTheTwist) {
  TrajectorySpec sin = twistSpec(Vec3(0.5, 0.0, 0.8), Vec3(0.1, -0.2, 0.3));
  sin.kind = TrajectoryKind::Sinusoid;
  sin.amplitude_v = Vec3(0.3, 0.2, 0.0);
  sin.amplitude_w = Vec3(0.0, 0.5, 0.1);
  sin.frequency = 2.0;
  TrajectorySpec pw;
  pw.kind = TrajectoryKind::Piecewise;
  pw.segments = {{0.2, Vec3(1, 0, 0), Vec3(0, 0.5, 0)}, {0.3, Vec3(0, 1, 0.2), Vec3(0.2, 0, 0)}};
  TrajectorySpec acc = twistSpec(Vec3(0.5, 0.0, 0.8), Vec3(0.4, -0.9, 0.3));
  acc.kind = TrajectoryKind::ConstantAcceleration;
  acc.acceleration = Vec3(1.5, -0.5, 2.0);
  acc.initial.R = so3::exp(Vec3(0.2, 0.3, -0.1));
  for (const TrajectorySpec& s : {sin, pw, acc}) {
    const Trajectory tr(s, 1.0);
    for (double t : {0.05, 0.13, 0.27, 0.44}) {
      const double h = 1e-5;
      const RigidPose a = tr.pose(t - h), b = tr.pose(t + h), c = tr.pose(t);
      const Vec3 v_cam = c.R.transpose() * (b.p - a.p) / (2 * h);
      const Vec3 w_cam = so3::log(a.R.transpose() * b.R) / (2 * h);
      EXPECT_LT((v_cam - tr.linearVelocity(t)).norm(), 1e-5) << toString(s.kind) << " t=" << t;
      EXPECT_LT((w_cam - tr.angularVelocity(t)).norm(), 1e-5) << toString(s.kind) << " t=" << t;
    }
    // Continuity (piecewise: at the segment boundary).
    const RigidPose a = tr.pose(0.2 - 1e-9), b = tr.pose(0.2 + 1e-9);
    EXPECT_LT((a.p - b.p).norm(), 1e-8);
    EXPECT_LT((a.R - b.R).norm(), 1e-8);
  }
}

// A constant acceleration is world-fixed: the pose's second difference is
// R0 a at every time, and linearVelocityRate is dv/dt of the camera-frame v.
TEST(SimTrajectory, ConstantAccelerationIsFixedInTheWorld) {
  TrajectorySpec s = twistSpec(Vec3(0.3, 0.1, 1.0), Vec3(0.5, 1.2, -0.4));
  s.kind = TrajectoryKind::ConstantAcceleration;
  s.acceleration = Vec3(-1.0, 2.0, 0.5);
  s.initial.R = so3::exp(Vec3(-0.3, 0.1, 0.4));
  const Trajectory tr(s, 1.0);
  for (double t : {0.0, 0.21, 0.63}) {
    const double h = 1e-3;
    const Vec3 second = (tr.pose(t + h).p - 2.0 * tr.pose(t).p + tr.pose(t - h).p) / (h * h);
    EXPECT_LT((second - s.initial.R * s.acceleration).norm(), 1e-6) << "t=" << t;
    const Vec3 rate = (tr.linearVelocity(t + 1e-6) - tr.linearVelocity(t - 1e-6)) / 2e-6;
    EXPECT_LT((rate - tr.linearVelocityRate(t)).norm(), 1e-6) << "t=" << t;
  }
  EXPECT_LT((tr.linearVelocity(0.0) - s.v).norm(), 1e-15);
  EXPECT_EQ(parseTrajectoryKind("constant_acceleration"), TrajectoryKind::ConstantAcceleration);
  s.acceleration.x() = NAN;
  EXPECT_NE(s.validate().find("acceleration"), std::string::npos);
}

TEST(SimImu, GyroEqualsTheTwistInTheImuFrame) {
  TrajectorySpec s = twistSpec(Vec3(0.5, -0.2, 1.0), Vec3(0.3, 0.1, -0.4));
  s.kind = TrajectoryKind::Sinusoid;
  s.amplitude_w = Vec3(0.2, 0.0, 0.3);
  s.frequency = 3.0;
  const Trajectory tr(s, 1.0);
  ImuOptions o;
  o.gyro_noise = 0.0;
  o.accel_noise = 0.0;
  o.R_cam_imu = so3::exp(Vec3(0.0, M_PI / 2, 0.1));
  const auto imu = simulateImu(tr, o, 0.0, 0.5, 3);
  ASSERT_EQ(imu.size(), 501u);  // 1 kHz, both ends included
  for (const auto& m : imu) {
    ASSERT_LT((o.R_cam_imu * m.gyro - tr.angularVelocity(m.t)).norm(), 1e-12);
    // accel = R_imu_cam (dv/dt + w x v - R_world_cam^T g)
    const Vec3 f = tr.linearVelocityRate(m.t) +
                   tr.angularVelocity(m.t).cross(tr.linearVelocity(m.t)) -
                   tr.pose(m.t).R.transpose() * o.gravity;
    ASSERT_LT((o.R_cam_imu * m.accel - f).norm(), 1e-9);
  }
  // Noise and bias: the mean error is the bias, the spread the noise density * sqrt(rate).
  o.gyro_noise = 1e-3;
  o.gyro_bias = Vec3(0.01, -0.02, 0.005);
  const auto noisy = simulateImu(tr, o, 0.0, 0.5, 3);
  Vec3 mean = Vec3::Zero();
  double var = 0.0;
  for (const auto& m : noisy) {
    const Vec3 e = m.gyro - o.R_cam_imu.transpose() * tr.angularVelocity(m.t);
    mean += e;
  }
  mean /= noisy.size();
  for (const auto& m : noisy)
    var += (m.gyro - o.R_cam_imu.transpose() * tr.angularVelocity(m.t) - mean).squaredNorm();
  const double sigma = std::sqrt(var / (3.0 * noisy.size()));
  EXPECT_NEAR(sigma, 1e-3 * std::sqrt(1000.0), 0.1 * 1e-3 * std::sqrt(1000.0));
  EXPECT_LT((mean - o.gyro_bias).norm(), 5 * sigma / std::sqrt(noisy.size()));
}

namespace {
std::string writeFile(const fs::path& dir, const std::string& name, const std::string& text) {
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p.string();
}
const char* kSmallScene = R"(seed: 3
duration: 0.05
camera: {preset: davis240, width: 64, height: 48, fx: 60, fy: 60, cx: 31.5, cy: 23.5}
planes:
  - texture: chessboard
    position: [0, 0, 1]
    square: 0.1
    squares: [40, 30]
trajectory: {type: constant_twist, v: [1, 0.2, 0], w: [0, 0.1, 0.2]}
events: {noise_rate: 2.0}
)";
std::string loadError(const std::string& text) {
  const std::string path = writeFile(tempDir("cfg"), "bad.yaml", text);
  try {
    loadSynthConfig(path);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(SimConfig, RejectsUnknownKeysAndWrongTypesNamingKeyAndFile) {
  const std::string ok = kSmallScene;
  EXPECT_EQ(loadError(ok), "");
  std::string e = loadError(ok + "colour: red\n");
  EXPECT_NE(e.find("bad.yaml:11: unknown key 'colour'"), std::string::npos) << e;
  e = loadError(std::string(kSmallScene) + "imu: {rate: fast}\n");
  EXPECT_NE(e.find("key 'imu.rate': expected a number"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.yaml:11"), std::string::npos) << e;
  // A key that does not apply to the texture.
  e = loadError("planes:\n  - texture: rectangles\n    square: 0.1\n");
  EXPECT_NE(e.find("bad.yaml:3: unknown key 'planes[0].square'"), std::string::npos) << e;
  e = loadError("planes:\n  - {texture: chessboard}\ntrajectory: {v: [1, 2]}\n");
  EXPECT_NE(e.find("key 'trajectory.v': expected a list of 3 numbers"), std::string::npos) << e;
  e = loadError("planes:\n  - {texture: chessboard}\nevents: {refractory: -1}\n");
  EXPECT_NE(e.find("refractory"), std::string::npos) << e;
  e = loadError("planes:\n  - {texture: chessboard}\nevents: {threads: 1.5}\n");
  EXPECT_NE(e.find("key 'events.threads': expected an integer"), std::string::npos) << e;
  e = loadError("planes: []\n");
  EXPECT_NE(e.find("key 'planes': expected a non-empty list"), std::string::npos) << e;
  e = loadError("planes:\n  - {texture: marble}\n");
  EXPECT_NE(e.find("expected one of chessboard, rectangles, segments, got 'marble'"), std::string::npos) << e;
  e = loadError("planes: [\n");
  EXPECT_NE(e.find("YAML syntax"), std::string::npos) << e;
  e = loadError("planes:\n  - {texture: chessboard}\nimu: {R_cam_imu: [1,0,0, 0,1,0, 0,0,2]}\n");
  EXPECT_NE(e.find("key 'imu.R_cam_imu': must be a rotation matrix"), std::string::npos) << e;
  // Hostile values: NaN, huge sizes.
  e = loadError("planes:\n  - {texture: chessboard}\nevents: {noise_rate: .nan}\n");
  EXPECT_NE(e.find("key 'events.noise_rate': expected a number, got '.nan'"), std::string::npos) << e;
  e = loadError("camera: {width: 100000}\nplanes:\n  - {texture: chessboard}\n");
  EXPECT_NE(e.find("camera.width"), std::string::npos) << e;
  e = loadError("planes:\n  - {texture: segments, count: 10000000}\n");
  EXPECT_NE(e.find("key 'planes[0].count': must be in [0, 5000]"), std::string::npos) << e;
  fs::remove_all(tempDir("cfg"));
}

TEST(SimConfig, BundledScenesLoad) {
  int n = 0;
  for (const auto& f : fs::directory_iterator(CELC_SOURCE_DIR "/config/scenes")) {
    if (f.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(loadSynthConfig(f.path().string())) << f.path();
    ++n;
  }
  EXPECT_GE(n, 2);
}

TEST(SimSequence, WritesTheRpgLayout) {
  const fs::path dir = tempDir("seq");
  SynthConfig cfg = loadSynthConfig(writeFile(dir.string() + "_cfg", "s.yaml", kSmallScene));
  const SynthSummary s = writeSequence(cfg, dir.string());
  for (const char* f : {"events.txt", "labels.txt", "imu.txt", "groundtruth.txt", "twist.txt",
                        "calib.txt", "calib.yaml", "twist.yaml", "edges.txt"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  for (const auto& f : fs::directory_iterator(dir))
    EXPECT_EQ(f.path().filename().string().find(".partial"), std::string::npos) << f.path();
  // events.txt: "t x y p", 6 decimals, sorted; labels.txt: one line per event.
  std::ifstream ev(dir / "events.txt"), lab(dir / "labels.txt");
  std::string line, tstr;
  int64_t n = 0, prev = -1, on = 0;
  while (std::getline(ev, line)) {
    std::istringstream is(line);
    int x, y, p, label;
    ASSERT_TRUE(is >> tstr >> x >> y >> p) << line;
    const auto dot = tstr.find('.');
    ASSERT_EQ(tstr.size() - dot - 1, 6u) << line;
    const int64_t us = std::stoll(tstr.substr(0, dot)) * 1000000 + std::stoll(tstr.substr(dot + 1));
    ASSERT_GE(us, prev);
    prev = us;
    ASSERT_TRUE(x >= 0 && x < 64 && y >= 0 && y < 48 && (p == 0 || p == 1)) << line;
    ASSERT_TRUE(lab >> label);
    ASSERT_GE(label, -1);
    on += p;
    ++n;
  }
  int extra;
  EXPECT_FALSE(lab >> extra);
  EXPECT_EQ(n, s.events);
  EXPECT_EQ(on, s.stats.events_on);
  EXPECT_GT(n, 1000);
  EXPECT_EQ(s.imu_samples, 51);  // 1 kHz over 0.05 s
  EXPECT_EQ(s.poses, 11);        // 200 Hz
  // The twist recovered from consecutive ground-truth poses (what a consumer
  // computes) equals the configured one: T_rel = exp(twist dt) exactly.
  std::ifstream gt(dir / "groundtruth.txt");
  std::vector<std::array<double, 8>> poses;
  std::array<double, 8> row;
  while (gt >> row[0] >> row[1] >> row[2] >> row[3] >> row[4] >> row[5] >> row[6] >> row[7])
    poses.push_back(row);
  ASSERT_EQ(poses.size(), 11u);
  for (size_t k = 1; k < poses.size(); ++k) {
    auto toPose = [](const std::array<double, 8>& r) {
      const Eigen::Quaterniond q(r[7], r[4], r[5], r[6]);  // file order: qx qy qz qw
      return RigidPose{q.toRotationMatrix(), Vec3(r[1], r[2], r[3])};
    };
    const RigidPose rel = toPose(poses[k - 1]).inverse() * toPose(poses[k]);
    const double dt = poses[k][0] - poses[k - 1][0];
    const Vec3 phi = so3::log(rel.R);
    const Vec3 v = so3::leftJacobianInverse(phi) * rel.p / dt;
    EXPECT_LT((phi / dt - Vec3(0.0, 0.1, 0.2)).norm(), 1e-5);
    EXPECT_LT((v - Vec3(1.0, 0.2, 0.0)).norm(), 1e-5);
  }
  std::ifstream calib(dir / "calib.txt");
  double c[9];
  for (double& v : c) ASSERT_TRUE(calib >> v);
  EXPECT_EQ(c[0], 60.0);
  EXPECT_EQ(c[2], 31.5);
  // Re-writing the same config reproduces the same events (fixed seeds).
  const fs::path dir2 = tempDir("seq2");
  writeSequence(cfg, dir2.string());
  std::ifstream a(dir / "events.txt"), b(dir2 / "events.txt");
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
  fs::remove_all(dir);
  fs::remove_all(dir2);
  fs::remove_all(dir.string() + "_cfg");
}

TEST(SimSequence, CliRefusesExistingDirectoryWithoutForce) {
  const fs::path dir = tempDir("cli");
  const std::string cfg = writeFile(dir.string() + "_cfg", "s.yaml", kSmallScene);
  fs::create_directories(dir);
  writeFile(dir, "keep.txt", "x");
  const std::string base = std::string(CELC_BINARY) + " synth " + cfg + " -q -o " + dir.string();
  EXPECT_NE(std::system((base + " 2>/dev/null").c_str()), 0);
  EXPECT_FALSE(fs::exists(dir / "events.txt"));
  EXPECT_EQ(std::system((base + " --force --duration 0.02 --seed 4").c_str()), 0);
  EXPECT_TRUE(fs::exists(dir / "events.txt"));
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
  std::ifstream tw(dir / "twist.yaml");
  std::stringstream ts;
  ts << tw.rdbuf();
  EXPECT_NE(ts.str().find("seed: 4"), std::string::npos);
  EXPECT_NE(ts.str().find("duration: 0.02"), std::string::npos);
  fs::remove_all(dir);
  fs::remove_all(dir.string() + "_cfg");
}

// imu.still_before_s: the IMU starts that long before the motion, at rest at
// the initial pose (gyro 0, accelerometer minus gravity in the camera
// frame), and follows the trajectory from t = 0 on.
TEST(SimImu, StillBeforeTheMotionRestsAtTheInitialPose) {
  TrajectorySpec s = twistSpec(Vec3(0.5, -0.2, 1.0), Vec3(0.3, 0.1, -0.4));
  s.initial.R = so3::exp(Vec3(0.2, -0.1, 0.3));
  const Trajectory tr(s, 1.0);
  ImuOptions o;
  o.gyro_noise = 0.0;
  o.accel_noise = 0.0;
  o.still_before_s = 0.5;
  const auto imu = simulateImu(tr, o, -o.still_before_s, 0.2, 3);
  ASSERT_EQ(imu.size(), 701u);
  EXPECT_NEAR(imu.front().t, -0.5, 1e-12);
  for (const auto& m : imu) {
    if (m.t < 0.0) {
      ASSERT_LT(m.gyro.norm(), 1e-15) << "t=" << m.t;
      ASSERT_LT((m.accel + s.initial.R.transpose() * o.gravity).norm(), 1e-12) << "t=" << m.t;
    } else {
      ASSERT_LT((m.gyro - tr.angularVelocity(m.t)).norm(), 1e-12) << "t=" << m.t;
    }
  }
  o.still_before_s = -1.0;
  EXPECT_NE(o.validate().find("still_before_s"), std::string::npos);
}
