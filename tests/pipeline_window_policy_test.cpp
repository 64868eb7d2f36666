// The parallax window policy: the lines' translation D, the growth rule, and
// the joiner that grows windows from steps of a duration source.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "celc/geometry/so3.hpp"
#include "celc/io/writers.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/window_policy.hpp"
#include "io_test_util.hpp"

using namespace celc;
using celc::test::TempDir;

namespace {
// A cluster whose reference-frame lines m1 (at t1) and m3 (at t3) are `moved`
// apart (normalised units) at its centroid c, seen through `motion`: the
// camera-frame lines and events turn with the camera.
ClusterObservation clusterMoved(const MotionModel& motion, double t1, double t3, double moved, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.3, 0.3), angle(0.0, 3.14);
  const double a = angle(rng);
  const Eigen::Vector2d c(u(rng), u(rng)), n(std::cos(a), std::sin(a));
  const double rho1 = n.dot(c) - 0.5 * moved, rho3 = rho1 + moved;  // c halfway, as real events lie
  ClusterObservation cl;
  cl.l1.t = t1;
  cl.l3.t = t3;
  cl.l1.normal = (motion.rotation(t1).transpose() * Vec3(n.x(), n.y(), -rho1)).normalized();
  cl.l3.normal = -(motion.rotation(t3).transpose() * Vec3(n.x(), n.y(), -rho3)).normalized();  // sign is free
  // Events symmetric about c along the lines: their centroid is c.
  for (int k = -20; k <= 20; ++k) {
    const double t = t1 + (t3 - t1) * (k + 20) / 40.0;
    const Vec3 p(c.x() - n.y() * 0.01 * k, c.y() + n.x() * 0.01 * k, 1.0);
    cl.times.push_back(t);
    cl.bearings.push_back(motion.rotation(t).transpose() * p);
  }
  return cl;
}
}  // namespace

// D = median over clusters of f * (offset change at the centroid) * window /
// (t3 - t1), with the rotation removed: a camera turning at 2 rad/s moves the
// camera-frame lines by ~0.2 rad, which must not count.
TEST(WindowPolicy, LineTranslationIsTheMedianRotationFreeMotionOverTheWindow) {
  std::mt19937 rng(3);
  const MotionModel motion = MotionModel::constantTwist(Vec3(0.5, -1.8, 0.6), 0.0);
  WindowObservations obs;
  obs.focal_px = 320.0;
  // Offsets 0.01 .. 0.05 over [0.02, 0.08] s of a 0.1 s window: D_k = 320 * o_k * 0.1 / 0.06.
  for (double o : {0.05, 0.01, 0.03, 0.02, 0.04}) obs.clusters.push_back(clusterMoved(motion, 0.02, 0.08, o, rng));
  EXPECT_NEAR(lineTranslationPx(obs, motion, 0.0, 0.1), 320.0 * 0.03 * 0.1 / 0.06, 1e-6);
  // Clusters without lines do not count; fewer than 3 with lines: NaN.
  obs.clusters[0].has_lines = obs.clusters[1].has_lines = obs.clusters[2].has_lines = false;
  EXPECT_TRUE(std::isnan(lineTranslationPx(obs, motion, 0.0, 0.1)));
  EXPECT_NEAR(lineTranslationPx(obs, motion, 0.0, 0.1, 2), 320.0 * 0.04 * 0.1 / 0.06, 1e-6);  // median of 2: upper
  // A cluster whose lines span less than a quarter of the window does not count.
  WindowObservations short_lived;
  short_lived.focal_px = 320.0;
  for (int k = 0; k < 3; ++k) short_lived.clusters.push_back(clusterMoved(motion, 0.02, 0.04, 0.01, rng));
  EXPECT_TRUE(std::isnan(lineTranslationPx(short_lived, motion, 0.0, 0.1)));
  EXPECT_NEAR(lineTranslationPx(short_lived, motion, 0.0, 0.06), 320.0 * 0.01 * 0.06 / 0.02, 1e-6);
}

TEST(WindowPolicy, GrowthAimsAtTheTargetWithinOneAndAHalfToThreeTimes) {
  EXPECT_EQ(nextWindowSteps(2, 10.0, 25.0, 12), 5);   // 2.5x
  EXPECT_EQ(nextWindowSteps(2, 24.0, 25.0, 12), 3);   // at least 1.5x
  EXPECT_EQ(nextWindowSteps(2, 1.0, 25.0, 12), 6);    // at most 3x
  EXPECT_EQ(nextWindowSteps(2, NAN, 25.0, 12), 6);    // not measurable: 3x
  EXPECT_EQ(nextWindowSteps(8, 5.0, 25.0, 12), 12);   // capped
  EXPECT_EQ(nextWindowSteps(1, 24.9, 25.0, 12), 2);   // always grows
}

namespace {
struct JoinedWindow {
  double t0, t1;
  std::size_t events;
};
// Windows of the joiner over a text file of events with a probe D = rate * duration.
std::vector<JoinedWindow> joinAll(const std::string& file, const ParallaxWindowOptions& o, double rate_px_s,
                                  std::vector<double>* probed = nullptr, WindowTail* tail = nullptr) {
  auto reader = openEventSource(file);
  WindowOptions steps;
  steps.seconds_per_window = o.step_seconds;
  steps.keep_partial = true;
  steps.read_batch = 500;
  WindowSource source(*reader, steps);
  ParallaxWindowJoiner joiner(source, o, 0.5, [&](double t0, double t1, const std::vector<Event>& ev) {
    if (probed) probed->push_back(t1 - t0);
    EXPECT_FALSE(ev.empty());
    return rate_px_s * (t1 - t0);
  });
  std::vector<JoinedWindow> out;
  EventWindow w;
  while (joiner.next(w)) {
    EXPECT_EQ(w.index, out.size());
    out.push_back({w.t0, w.t1, w.events.size()});
  }
  if (tail) *tail = joiner.tail();
  return out;
}
}  // namespace

TEST(WindowPolicy, JoinerGrowsEachWindowUntilTheTargetOrTheMaximum) {
  TempDir d;
  const auto ev = celc::test::randomEvents(60000, 240, 180, 5, 1.0);  // ~0.6 s at 10 us per event
  writeEventsText(d.file("e.txt"), ev);
  ParallaxWindowOptions o;  // 25 px, 0.05 .. 0.3 s, steps of 0.025 s
  // 200 px/s: 0.05 s shows 10 px -> 0.125 s shows 25 px: windows of 5 steps after one probe.
  std::vector<double> probed;
  const auto w = joinAll(d.file("e.txt"), o, 200.0, &probed);
  ASSERT_GE(w.size(), 3u);
  EXPECT_NEAR(w[0].t1 - w[0].t0, 0.125, 1e-9);
  EXPECT_NEAR(probed[0], 0.05, 1e-9);
  EXPECT_NEAR(probed[1], 0.125, 1e-9);
  // Contiguous, in order, every event in exactly one window but the dropped tail.
  std::size_t total = 0;
  for (std::size_t k = 0; k < w.size(); ++k) {
    if (k > 0) {
      EXPECT_NEAR(w[k].t0, w[k - 1].t1, 1e-9);
    }
    total += w[k].events;
  }
  EXPECT_LE(total, ev.size());
  EXPECT_GE(total, ev.size() - 2600);  // at most a quarter of min_seconds (0.5 share) dropped
  // Later windows start from the last one's length: one probe each.
  EXPECT_NEAR(w[1].t1 - w[1].t0, 0.125, 1e-9);
  EXPECT_NEAR(probed[2], 0.125, 1e-9);
  // Two probes for the first window, at most one for each later one (none for
  // a last window cut by the data); starting each at min_seconds takes two each.
  EXPECT_LE(probed.size(), w.size() + 1);
  // No parallax at all: every window is max_seconds long (the last cut by the data).
  const auto flat = joinAll(d.file("e.txt"), o, 0.0);
  EXPECT_NEAR(flat[0].t1 - flat[0].t0, 0.3, 1e-9);
  // Much parallax: every window is min_seconds.
  const auto fast = joinAll(d.file("e.txt"), o, 1e4);
  EXPECT_NEAR(fast[0].t1 - fast[0].t0, 0.05, 1e-9);
  EXPECT_NEAR(fast[3].t0, fast[0].t0 + 0.15, 1e-9);
}

namespace {
// n random events (~10 us apart from t = 1 s) in a text file, read in steps
// of 0.025 s: what the parallax policy joins into windows.
struct StepStream {
  TempDir dir;
  std::unique_ptr<EventReader> reader;
  std::unique_ptr<WindowSource> source;
  explicit StepStream(std::size_t n) {
    writeEventsText(dir.file("e.txt"), celc::test::randomEvents(n, 240, 180, 5, 1.0));
    reader = openEventSource(dir.file("e.txt"));
    WindowOptions steps;
    steps.seconds_per_window = 0.025;
    steps.keep_partial = true;
    source = std::make_unique<WindowSource>(*reader, steps);
  }
};
}  // namespace

// A camera that speeds up: a window started at the last one's length that
// shows twice the target is shrunk once toward it.
TEST(WindowPolicy, JoinerShrinksWhenTheMotionSpeedsUp) {
  StepStream stream(100000);  // ~1 s from t = 1 s
  WindowSource& source = *stream.source;
  ParallaxWindowOptions o;
  // 100 px/s before t = 1.3 s (windows of 0.25 s), 1000 px/s after (0.025 s would do: min_seconds).
  ParallaxWindowJoiner joiner(source, o, 0.5, [](double t0, double t1, const std::vector<Event>&) {
    return (t0 < 1.3 ? 100.0 : 1000.0) * (t1 - t0);
  });
  EventWindow w;
  ASSERT_TRUE(joiner.next(w));
  EXPECT_NEAR(w.t1 - w.t0, 0.25, 1e-9);
  ASSERT_TRUE(joiner.next(w));  // starts at 1.25 s < 1.3: still slow, 0.25 s
  EXPECT_NEAR(w.t1 - w.t0, 0.25, 1e-9);
  ASSERT_TRUE(joiner.next(w));  // 0.25 s would show 250 px: shrunk to min_seconds
  EXPECT_NEAR(w.t1 - w.t0, 0.05, 1e-9);
  EXPECT_GE(joiner.translationPx(), o.target_px);
}

// A length is probed once per window: the room at 4 m/s shrinks a warm start
// of 0.075 s (67.5 px) to 0.05 s (22.3 px: D is not linear in the length
// there) and grows back to 0.075 s, whose D it already has.
TEST(WindowPolicy, JoinerProbesEachLengthOnce) {
  StepStream stream(30000);  // ~0.3 s from t = 1 s
  WindowSource& source = *stream.source;
  ParallaxWindowOptions o;  // 25 px, 0.05 .. 0.3 s, steps of 0.025 s
  std::vector<double> probed;
  ParallaxWindowJoiner joiner(source, o, 0.5, [&](double t0, double t1, const std::vector<Event>&) {
    probed.push_back(t1 - t0);
    if (t0 < 1.05) return 400.0 * (t1 - t0);  // the first window: 20 px at 0.05 s, 30 px at 0.075 s
    return t1 - t0 < 0.06 ? 22.3 : 67.5;      // the second: the room's two lengths
  });
  EventWindow w;
  ASSERT_TRUE(joiner.next(w));
  EXPECT_NEAR(w.t1 - w.t0, 0.075, 1e-9);
  ASSERT_EQ(probed.size(), 2u);
  ASSERT_TRUE(joiner.next(w));  // 0.075 s: 67.5 px, shrunk to 0.05 s: 22.3 px, back to 0.075 s
  EXPECT_NEAR(w.t1 - w.t0, 0.075, 1e-9);
  EXPECT_NEAR(joiner.translationPx(), 67.5, 1e-12);
  ASSERT_EQ(probed.size(), 4u);  // 0.075 s measured once
  EXPECT_NEAR(probed[2], 0.075, 1e-9);
  EXPECT_NEAR(probed[3], 0.05, 1e-9);
}

// A probe that finds no D on a longer window (fast motion ends the clusters
// early, or its subsample is too sparse to cluster) does not grow the window
// to max_seconds: after a finite D the window keeps the length aimed at from
// it, and a warm start that cannot be measured is measured again from
// min_seconds.
TEST(WindowPolicy, JoinerStopsGrowingWhenALongerWindowCannotBeMeasured) {
  StepStream stream(60000);  // ~0.6 s
  WindowSource& source = *stream.source;
  ParallaxWindowOptions o;  // 25 px, 0.05 .. 0.3 s
  std::vector<double> probed;
  // 200 px/s, but nothing measurable beyond 0.1 s.
  ParallaxWindowJoiner joiner(source, o, 0.5, [&](double t0, double t1, const std::vector<Event>&) {
    probed.push_back(t1 - t0);
    return t1 - t0 > 0.1 + 1e-9 ? NAN : 200.0 * (t1 - t0);
  });
  EventWindow w;
  ASSERT_TRUE(joiner.next(w));
  EXPECT_NEAR(w.t1 - w.t0, 0.125, 1e-9);  // aimed at from 10 px in 0.05 s, not 0.3 s
  EXPECT_TRUE(std::isnan(joiner.translationPx()));
  ASSERT_EQ(probed.size(), 2u);
  ASSERT_TRUE(joiner.next(w));  // warm start at 0.125 s: no D, so from 0.05 s again
  EXPECT_NEAR(w.t1 - w.t0, 0.125, 1e-9);
  ASSERT_EQ(probed.size(), 4u);  // 0.125 s, 0.05 s, then 0.125 s again from the first try
  EXPECT_NEAR(probed[2], 0.125, 1e-9);
  EXPECT_NEAR(probed[3], 0.05, 1e-9);
  // Never measurable: the window grows to max_seconds as before.
  StepStream stream2(60000);
  ParallaxWindowJoiner never(*stream2.source, o, 0.5, [](double, double, const std::vector<Event>&) { return NAN; });
  ASSERT_TRUE(never.next(w));
  EXPECT_NEAR(w.t1 - w.t0, 0.3, 1e-9);
}

// A camera that turns slowly may need more than max_seconds to show the
// target: the window grows on to slow_turn_max_seconds while the camera
// turns less than slow_turn_rad over it; a fast-turning one stops at
// max_seconds, and without a known rotation nothing grows past it.
TEST(WindowPolicy, JoinerGrowsPastMaxSecondsOnlyWhileTheCameraTurnsSlowly) {
  ParallaxWindowOptions o;  // 25 px, 0.05 .. 0.3 s; slowly turning: 1 s within 0.5 rad
  auto firstWindow = [&](double rate_rad_s, bool known) {
    StepStream stream(150000);  // ~1.5 s
    std::vector<double> probed;
    ParallaxWindowJoiner::Turn turn = [&](double t0, double t1) { return known ? rate_rad_s * (t1 - t0) : NAN; };
    // 20 px/s: 25 px would take 1.25 s.
    ParallaxWindowJoiner joiner(
        *stream.source, o, 0.5,
        [&](double t0, double t1, const std::vector<Event>&) {
          probed.push_back(t1 - t0);
          return 20.0 * (t1 - t0);
        },
        turn);
    EventWindow w;
    EXPECT_TRUE(joiner.next(w));
    return std::make_pair(w.t1 - w.t0, probed);
  };
  // 0.2 rad/s: grows 0.05 -> 0.15 -> 0.45 -> 1.0 s (capped), D measured at each.
  const auto [slow, slow_probed] = firstWindow(0.2, true);
  EXPECT_NEAR(slow, 1.0, 1e-9);
  ASSERT_EQ(slow_probed.size(), 4u);
  EXPECT_NEAR(slow_probed[2], 0.45, 1e-9);
  // 1.1 rad/s: 0.45 s turns 0.495 rad, 0.475 s 0.52: the longest is 0.45 s.
  EXPECT_NEAR(firstWindow(1.1, true).first, 0.45, 1e-9);
  // 2 rad/s turns 0.6 rad in 0.3 s: max_seconds, as without the rule.
  EXPECT_NEAR(firstWindow(2.0, true).first, 0.3, 1e-9);
  EXPECT_NEAR(firstWindow(0.2, false).first, 0.3, 1e-9);
  // The extension off: slow_turn_max_seconds at max_seconds.
  o.slow_turn_max_seconds = o.max_seconds;
  EXPECT_NEAR(firstWindow(0.2, true).first, 0.3, 1e-9);
  // Or a longer max_seconds alone.
  o.max_seconds = 0.6;
  EXPECT_NEAR(firstWindow(2.0, true).first, 0.6, 1e-9);
}

// The probe's subsample keeps its density in windows longer than max_seconds.
TEST(WindowPolicy, ProbeBudgetGrowsPastMaxSeconds) {
  ParallaxWindowOptions o;  // 30,000 events per 0.3 s
  EXPECT_EQ(o.probeBudget(0.05), 30000u);
  EXPECT_EQ(o.probeBudget(0.3), 30000u);
  EXPECT_EQ(o.probeBudget(0.45), 45000u);
  EXPECT_EQ(o.probeBudget(1.0), 100000u);
}

// The rest of the data after a window that showed the target is joined to
// it when the rest is too short to show the target itself (D linear in the
// length) and the joined window stays within the longest one.
TEST(WindowPolicy, JoinerJoinsARestTooShortToShowTheTarget) {
  ParallaxWindowOptions o;  // 25 px, 0.05 .. 0.3 s, steps of 0.025 s
  auto windows = [&](std::size_t n, double rate_px_s) {
    TempDir d;
    const auto ev = celc::test::randomEvents(n, 240, 180, 5, 1.0);  // 10 +- 6 us apart
    writeEventsText(d.file("e.txt"), ev);
    WindowTail tail;
    const auto w = joinAll(d.file("e.txt"), o, rate_px_s, nullptr, &tail);
    std::size_t total = 0;
    for (const auto& x : w) total += x.events;
    EXPECT_EQ(total + (tail.emitted ? 0 : tail.events), ev.size());
    return w;
  };
  // 200 px/s: windows of 0.125 s. 0.54 s: four windows and 0.04 s left: joined.
  auto w = windows(54000, 200.0);
  ASSERT_EQ(w.size(), 4u);
  EXPECT_NEAR(w[3].t1 - w[3].t0, 0.175, 1e-9);
  EXPECT_NEAR(w[2].t1 - w[2].t0, 0.125, 1e-9);
  // 0.58 s: 0.08 s left (16 px), still shorter than the window: joined.
  w = windows(58000, 200.0);
  ASSERT_EQ(w.size(), 4u);
  EXPECT_NEAR(w[3].t1 - w[3].t0, 0.225, 1e-9);
  // 0.64 s: five windows and 0.015 s left: joined.
  w = windows(64000, 200.0);
  ASSERT_EQ(w.size(), 5u);
  EXPECT_NEAR(w[4].t1 - w[4].t0, 0.15, 1e-9);
  // 50 px/s: every window is 0.3 s long and below the target; what is left
  // after them is a window of its own.
  w = windows(54000, 50.0);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NEAR(w[0].t1 - w[0].t0, 0.3, 1e-9);
  EXPECT_NEAR(w[1].t0 - w[0].t0, 0.3, 1e-9);
  // D of 60 px whatever the length: windows of min_seconds (0.05 s), and a
  // rest of one step would show the target: a window of its own (emitted at
  // a quarter of min_seconds here).
  {
    TempDir d;
    writeEventsText(d.file("e.txt"), celc::test::randomEvents(51500, 240, 180, 5, 1.0));  // 0.515 s
    auto reader = openEventSource(d.file("e.txt"));
    WindowOptions steps;
    steps.seconds_per_window = o.step_seconds;
    steps.keep_partial = true;
    WindowSource source(*reader, steps);
    ParallaxWindowJoiner joiner(source, o, 0.25, [](double, double, const std::vector<Event>&) { return 60.0; });
    std::vector<double> lengths;
    EventWindow ew;
    while (joiner.next(ew)) lengths.push_back(ew.t1 - ew.t0);
    ASSERT_EQ(lengths.size(), 11u);
    EXPECT_NEAR(lengths[9], 0.05, 1e-9);
    EXPECT_NEAR(lengths[10], 0.025, 1e-9);
  }
  // A longest window of 0.15 s has no room for the 0.04 s: not joined.
  o.max_seconds = 0.15;
  o.slow_turn_max_seconds = 0.15;
  w = windows(54000, 200.0);
  ASSERT_EQ(w.size(), 5u);
  EXPECT_NEAR(w[3].t1 - w[3].t0, 0.125, 1e-9);
}

TEST(WindowPolicy, JoinerReportsTheShortLastWindow) {
  TempDir d;
  auto ev = celc::test::randomEvents(10000, 240, 180, 9, 1.0);  // ~0.1 s
  writeEventsText(d.file("e.txt"), ev);
  ParallaxWindowOptions o;
  o.min_seconds = o.max_seconds = 0.075;  // three steps: 0.075 s, then ~0.025 s left
  WindowTail tail;
  const auto w = joinAll(d.file("e.txt"), o, 0.0, nullptr, &tail);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_FALSE(tail.emitted);
  EXPECT_GT(tail.events, 0u);
  EXPECT_EQ(w[0].events + tail.events, ev.size());
  EXPECT_LT(tail.share, 0.5);
}

// Options: the policy decides which keys apply; a key of another policy is an
// error naming it, not silently ignored.
TEST(WindowPolicy, PolicyKeysAreCheckedAgainstThePolicy) {
  auto error = [](const std::string& yaml) {
    RunConfig c;
    try {
      applyRunConfig(yaml, "test.yaml", c);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(RunConfig{}.window_policy, WindowPolicy::Parallax);
  EXPECT_EQ(RunConfig{}.validate(), "");
  EXPECT_EQ(error("windows: {policy: seconds, seconds: 0.1}"), "");
  EXPECT_EQ(error("windows: {policy: events, events: 30000}"), "");
  EXPECT_NE(error("windows: {policy: events}").find("windows.events"), std::string::npos);
  EXPECT_NE(error("windows: {seconds: 0.1}").find("windows.policy"), std::string::npos);
  EXPECT_NE(error("windows: {policy: seconds, seconds: 0.1, events: 5}").find("windows.events"), std::string::npos);
  EXPECT_NE(error("windows: {policy: widest}").find("policy"), std::string::npos);
  EXPECT_NE(error("windows: {min_seconds: 0.2, max_seconds: 0.1}").find("windows.max_seconds"), std::string::npos);
  EXPECT_NE(error("windows: {overlap: 0.5}").find("windows.overlap"), std::string::npos);
  EXPECT_NE(error("windows: {parallax_px: .nan}").find("windows.parallax_px"), std::string::npos);
  EXPECT_EQ(error("windows: {parallax_px: 20, no_parallax_px: 20}"), "");
  EXPECT_NE(error("windows: {parallax_px: 20, no_parallax_px: 21}").find("windows.no_parallax_px: must be in [0, parallax_px (20)]"),
            std::string::npos);
  EXPECT_NE(error("windows: {no_parallax_px: -1}").find("windows.no_parallax_px"), std::string::npos);
  EXPECT_EQ(error("windows: {max_seconds: 2, slow_turn_max_seconds: 0.5}"), "");  // the extension off
  EXPECT_NE(error("windows: {slow_turn_max_seconds: 0}").find("windows.slow_turn_max_seconds"), std::string::npos);
  EXPECT_NE(error("windows: {slow_turn_max_seconds: .inf}").find("windows.slow_turn_max_seconds"), std::string::npos);
  EXPECT_NE(error("windows: {slow_turn_max_seconds: 300}").find("windows.slow_turn_max_seconds: more than 10000"),
            std::string::npos);
  EXPECT_NE(error("windows: {slow_turn_rad: -0.1}").find("windows.slow_turn_rad"), std::string::npos);
  // --set: keys that belong together are validated together, in any order.
  RunConfig c;
  applyRunSettings({"windows.seconds=0.1", "windows.policy=seconds"}, c);
  EXPECT_EQ(c.window_policy, WindowPolicy::Seconds);
  EXPECT_EQ(c.windows.seconds_per_window, 0.1);
  RunConfig d;
  EXPECT_THROW(applyRunSettings({"windows.seconds=0.1"}, d), std::exception);
  EXPECT_EQ(d.window_policy, WindowPolicy::Parallax);  // unchanged after an error
  EXPECT_EQ(d.windows.seconds_per_window, 0.0);
}
