// Events turned back by the rotation (celc::derotateEvents) on labelled
// synthetic windows: under pure rotation an edge stays in one place, the
// clustering then keeps each line whole, and what cannot be projected is
// noise.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <map>
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/cluster/derotate.hpp"
#include "celc/cluster/synthetic.hpp"

namespace celc {
namespace {

LabelledWindow turningWindow(unsigned seed, double speed_m_per_s, double omega_rad_per_s, double duration_s = 0.1) {
  LabelledWindowOptions o;
  o.duration_s = duration_s;
  o.n_events = static_cast<int>(300000 * duration_s);
  o.seed = seed;
  o.speed_m_per_s = speed_m_per_s;
  o.omega_rad_per_s = omega_rad_per_s;
  return generateLabelledWindow(o);
}

std::vector<Event> derotated(const LabelledWindow& w, double t_ref) {
  const MotionModel motion = MotionModel::constantTwist(w.omega, 0.0);
  return derotateEvents(w.events, [&](const Vec2& p) { return w.camera.bearing(p); }, w.camera, motion, t_ref);
}

/// RMS distance [px] of each true line's events to the straight image line
/// fitted to them (total least squares), worst line.
double worstLineRmsPx(const std::vector<Event>& events, const std::vector<int>& labels) {
  std::map<int, std::vector<Vec2>> by_line;
  for (std::size_t i = 0; i < events.size(); ++i)
    if (labels[i] >= 0 && std::isfinite(events[i].x)) by_line[labels[i]].push_back(Vec2(events[i].x, events[i].y));
  double worst = 0.0;
  for (const auto& [line, points] : by_line) {
    Vec2 mean = Vec2::Zero();
    for (const Vec2& p : points) mean += p;
    mean /= static_cast<double>(points.size());
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const Vec2& p : points) scatter += (p - mean) * (p - mean).transpose();
    const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues()(0);
    worst = std::max(worst, std::sqrt(std::max(0.0, smallest) / static_cast<double>(points.size())));
  }
  return worst;
}

/// Lines with at least 80% of their events in one cluster.
int wholeLines(const LabelledWindow& w, const ClusterResult& r) {
  std::map<std::pair<int, int>, int> joint;
  std::map<int, int> line_size;
  for (std::size_t i = 0; i < w.events.size(); ++i) {
    if (w.labels[i] < 0) continue;
    ++line_size[w.labels[i]];
    if (r.labels[i] >= 0) ++joint[{w.labels[i], r.labels[i]}];
  }
  int whole = 0;
  for (const auto& [line, n] : line_size) {
    int best = 0;
    for (const auto& [key, k] : joint)
      if (key.first == line) best = std::max(best, k);
    whole += best >= 0.8 * n ? 1 : 0;
  }
  return whole;
}

// A camera only turning (3 rad/s for 0.1 s: the lines sweep about 60 px):
// turned back, each line's events over the whole window lie on one image
// line within the pixel noise (0.7 px before rounding: about 0.75 px RMS);
// as recorded they spread over the sweep.
TEST(Derotate, PureRotationKeepsEachEdgeInOnePlace) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const LabelledWindow w = turningWindow(seed, 0.0, 3.0);
    EXPECT_GT(worstLineRmsPx(w.events, w.labels), 5.0) << "seed " << seed;
    EXPECT_LT(worstLineRmsPx(derotated(w, 0.05), w.labels), 1.0) << "seed " << seed;
  }
}

// Without rotation the events keep their pixels, moved to the grid's centre;
// time, polarity and order are kept.
TEST(Derotate, NoRotationOnlyMovesTheOrigin) {
  LabelledWindow w = turningWindow(4, 1.0, 0.0);
  const MotionModel still = MotionModel::constantTwist(Vec3::Zero(), 0.0);
  const std::vector<Event> out =
      derotateEvents(w.events, [&](const Vec2& p) { return w.camera.bearing(p); }, w.camera, still, 0.05);
  ASSERT_EQ(out.size(), w.events.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_NEAR(out[i].x, w.events[i].x - w.camera.cx + kDerotatedCentrePx, 1e-3);
    EXPECT_NEAR(out[i].y, w.events[i].y - w.camera.cy + kDerotatedCentrePx, 1e-3);
    EXPECT_EQ(out[i].t, w.events[i].t);
    EXPECT_EQ(out[i].on, w.events[i].on);
  }
}

// Under fast rotation the growing on the recorded events cuts the lines into
// pieces; on the turned-back events it keeps them whole. Three draws of 8
// lines with some translation (1 m/s, 1.5-4 m away) in 0.3 s windows at 3
// rad/s (the lines sweep about 180 px): measured 4 of 22 lines with 80% of
// their events in one cluster as recorded, 16 of 22 turned back.
TEST(Derotate, FastRotationClustersEachLineWhole) {
  int lines = 0, whole_recorded = 0, whole_derotated = 0;
  ClusterOptions options;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const LabelledWindow w = turningWindow(seed, 1.0, 3.0, 0.3);
    lines += w.n_lines();
    whole_recorded += wholeLines(w, clusterEvents(w.events, options));
    whole_derotated += wholeLines(w, clusterEvents(derotated(w, 0.15), options));
  }
  EXPECT_GE(whole_derotated, whole_recorded + 0.3 * lines) << whole_derotated << " against " << whole_recorded;
  EXPECT_GE(whole_derotated, 0.6 * lines) << whole_derotated << " of " << lines;
}

// A bearing turned 60 deg or more from the optical axis, or a time that is
// not finite, gives NaN coordinates, which the clustering labels noise.
TEST(Derotate, WhatCannotBeProjectedIsNoise) {
  CameraModel camera;
  std::vector<Event> events = {{0.0, 173.0f, 130.0f, true}, {1.0, 173.0f, 130.0f, true},
                               {NAN, 173.0f, 130.0f, false}};
  // 1.2 rad (69 deg) about y in the first second: the axis at t = 1 s is 69 deg
  // from the axis at t = 0.
  const MotionModel motion = MotionModel::constantTwist(Vec3(0.0, 1.2, 0.0), 0.0);
  const std::vector<Event> out =
      derotateEvents(events, [&](const Vec2& p) { return camera.bearing(p); }, camera, motion, 0.0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NEAR(out[0].x, kDerotatedCentrePx, 1e-3);
  EXPECT_TRUE(std::isnan(out[1].x) && std::isnan(out[1].y));
  EXPECT_TRUE(std::isnan(out[2].x) && std::isnan(out[2].y));
}

}  // namespace
}  // namespace celc
