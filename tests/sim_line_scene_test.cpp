// Events that sit a constant distance off their edge (LineSceneOptions::edge_offset_px).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "celc/sim/line_scene.hpp"
#include "celc/solver/solver.hpp"

using namespace celc;

namespace {

// Signed pixel distance of a pixel to the projection of a segment at time t.
double distanceToProjectedLine(const LineSceneTrial& tr, const CameraModel& cam,
                               const std::array<Vec3, 2>& seg, const Vec3& velocity, double t,
                               const Vec2& px) {
  auto project = [&](const Vec3& X) {
    const Mat3 R = tr.true_motion.rotation(t);
    const Vec3 p = tr.true_motion.positionMatrix(t) * velocity;
    return cam.project(R.transpose() * (X - p));
  };
  const Vec2 a = project(seg[0]), b = project(seg[1]);
  const Vec2 n = Vec2(-(b - a).y(), (b - a).x()).normalized();
  return n.dot(px - a);
}

}  // namespace

// The generator moves every event of a line by exactly edge_offset_px along
// the line's image normal, to one side per line.
TEST(LineScene, EdgeOffsetMovesEventsOffTheirLine) {
  LineSceneOptions o;
  o.event_noise_px = 0.0;
  o.line_noise_px = 0.0;
  o.edge_offset_px = 0.3;
  std::mt19937_64 rng(3);
  const LineSceneTrial tr = generateLineScene(o, rng);
  std::vector<int> side(static_cast<size_t>(o.n_lines), 0);
  for (size_t k = 0; k < tr.pixel_events.size(); ++k) {
    const int line = tr.labels[k];
    ASSERT_GE(line, 0);
    const Event& e = tr.pixel_events[k];
    const double d = distanceToProjectedLine(tr, o.camera, tr.segments[static_cast<size_t>(line)],
                                             o.velocity, e.t, Vec2(e.x, e.y));
    // Pixels are stored as float: ~1e-4 px at these coordinates.
    EXPECT_NEAR(std::abs(d), 0.3, 1e-3);
    const int s = d > 0 ? 1 : -1;
    if (side[static_cast<size_t>(line)] == 0) side[static_cast<size_t>(line)] = s;
    EXPECT_EQ(side[static_cast<size_t>(line)], s) << "one side per line";
  }
}
