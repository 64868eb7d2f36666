// Window source over readers, and the gyroscope over a window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "celc/geometry/so3.hpp"
#include "celc/io/imu_window.hpp"
#include "celc/io/window_source.hpp"
#include "celc/io/writers.hpp"
#include "io_test_util.hpp"

using namespace celc;
using namespace celc;
using celc::test::TempDir;
using celc::test::writeBytes;

TEST(IoWindow, CountWindowsCoverTheFileInOrder) {
  TempDir d;
  const auto ev = celc::test::randomEvents(10500, 240, 180, 7);
  writeEventsText(d.file("e.txt"), ev);
  auto r = openEventSource(d.file("e.txt"));
  WindowOptions o;
  o.events_per_window = 1000;
  o.read_batch = 300;
  WindowSource ws(*r, o);
  EventWindow w;
  std::size_t k = 0;
  while (ws.next(w)) {
    ASSERT_EQ(w.events.size(), 1000u);
    EXPECT_EQ(w.index, k);
    EXPECT_NEAR(w.events.front().t, ev[k * 1000].t, 1e-9);
    EXPECT_NEAR(w.t1, ev[k * 1000 + 999].t, 1e-9);
    ++k;
  }
  EXPECT_EQ(k, 10u);  // the last 500 events do not make a full window
  EXPECT_LE(ws.peakBuffered(), 1000u + 300u);  // memory bounded by window + batch
  // keep_partial returns them
  auto r2 = openEventSource(d.file("e.txt"));
  o.keep_partial = true;
  WindowSource ws2(*r2, o);
  std::size_t total = 0;
  while (ws2.next(w)) total += w.events.size();
  EXPECT_EQ(total, 10500u);
}

TEST(IoWindow, CountWindowsWithOverlap) {
  TempDir d;
  const auto ev = celc::test::randomEvents(5000, 240, 180, 8);
  writeAedat2(d.file("e.aedat"), ev, {});
  auto r = openEventSource(d.file("e.aedat"));
  WindowOptions o;
  o.events_per_window = 1000;
  o.overlap = 0.5;
  WindowSource ws(*r, o);
  EventWindow w;
  std::size_t k = 0;
  while (ws.next(w)) {
    EXPECT_NEAR(w.events.front().t, ev[k * 500].t, 1e-9);
    EXPECT_NEAR(w.events.back().t, ev[k * 500 + 999].t, 1e-9);
    ++k;
  }
  EXPECT_EQ(k, 9u);  // starts 0, 500, ..., 4000
}

TEST(IoWindow, DurationWindowsHalfOpenWithRange) {
  TempDir d;
  // one event every 1 ms from t = 1.000 to 1.999
  std::vector<Event> ev(1000);
  for (int i = 0; i < 1000; ++i) ev[std::size_t(i)].t = 1.0 + 1e-3 * i, ev[std::size_t(i)].x = 1, ev[std::size_t(i)].y = 2;
  writeEventsText(d.file("e.txt"), ev);
  auto r = openEventSource(d.file("e.txt"));
  WindowOptions o;
  o.seconds_per_window = 0.1;
  o.t_start = 1.2;
  o.t_end = 1.6;
  o.read_batch = 64;
  WindowSource ws(*r, o);
  EventWindow w;
  std::vector<std::size_t> counts;
  while (ws.next(w)) {
    for (const auto& e : w.events) {
      EXPECT_GE(e.t, w.t0);
      EXPECT_LT(e.t, w.t1);
    }
    counts.push_back(w.events.size());
  }
  // [1.2,1.3) [1.3,1.4) [1.4,1.5) [1.5,1.6): complete, since the stream goes past t_end
  ASSERT_EQ(counts.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(double(counts[i]), 100.0, 1.0);
  EXPECT_LE(ws.peakBuffered(), 100u + 64u);
}

TEST(IoWindow, DurationWindowsOverlapAndEmptyGap) {
  TempDir d;
  std::vector<Event> ev;
  for (int i = 0; i < 100; ++i) ev.push_back({0.001 * i, 1, 1, true});
  for (int i = 0; i < 100; ++i) ev.push_back({1.0 + 0.001 * i, 1, 1, true});  // gap 0.1 .. 1.0
  writeEventsText(d.file("e.txt"), ev);
  auto r = openEventSource(d.file("e.txt"));
  WindowOptions o;
  o.seconds_per_window = 0.05;
  o.overlap = 0.5;
  WindowSource ws(*r, o);
  EventWindow w;
  int empty = 0, n = 0;
  while (ws.next(w)) {
    EXPECT_NEAR(w.t0, 0.025 * n, 1e-12);
    empty += w.events.empty();
    ++n;
  }
  EXPECT_GT(empty, 30);  // windows in the gap are returned, empty
}

TEST(IoWindow, InvalidOptions) {
  TempDir d;
  writeEventsText(d.file("e.txt"), celc::test::randomEvents(10, 10, 10, 1));
  auto r = openEventSource(d.file("e.txt"));
  WindowOptions o;
  EXPECT_THROW(WindowSource(*r, o), std::invalid_argument);  // neither N nor S
  o.events_per_window = 10;
  o.seconds_per_window = 1.0;
  EXPECT_THROW(WindowSource(*r, o), std::invalid_argument);  // both
  o.seconds_per_window = 0.0;
  o.overlap = 1.0;
  EXPECT_THROW(WindowSource(*r, o), std::invalid_argument);
  o.overlap = 0.0;
  o.t_start = 2.0, o.t_end = 1.0;
  EXPECT_THROW(WindowSource(*r, o), std::invalid_argument);
  o.t_start = std::nan("");
  EXPECT_FALSE(o.validate().empty());
}

// ---- gyroscope over a window ------------------------------------------------------

namespace {
/// Samples of a linear-in-time rate w(t) = a + b t (IMU frame) every dt from t0 to t1.
std::vector<ImuSample> linearGyro(const Vec3& a, const Vec3& b, double t0, double t1, double dt) {
  std::vector<ImuSample> s;
  for (double t = t0; t <= t1 + 1e-12; t += dt) {
    ImuSample x;
    x.t = t;
    x.gyro = a + b * t;
    s.push_back(x);
  }
  return s;
}
}  // namespace

TEST(IoGyro, MeanOfLinearSignalIsExactInCameraFrameWithOffset) {
  const Vec3 a(0.1, -0.2, 0.3), b(1.0, 0.5, -2.0);
  const Mat3 R = so3::exp(Vec3(0.3, -0.2, 1.0));
  const double off = 0.0031;
  GyroTrack g(linearGyro(a, b, 0.0, 1.0, 0.005), R, off);
  const double t0 = 0.2137, t1 = 0.4521;  // camera time
  const GyroWindow w = g.window(t0, t1);
  ASSERT_TRUE(w.ok());
  // w_cam(t) = R (a + b (t - off)); its mean over [t0, t1) is at the midpoint
  const Vec3 expect = R * (a + b * (0.5 * (t0 + t1) - off));
  EXPECT_LT((w.mean_omega - expect).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(w.times.front(), t0);
  EXPECT_DOUBLE_EQ(w.times.back(), t1);
  EXPECT_LT((w.rates.front() - R * (a + b * (t0 - off))).norm(), 1e-12);  // interpolated end
  EXPECT_LT((g.rateAt(0.3) - R * (a + b * (0.3 - off))).norm(), 1e-12);
}

TEST(IoGyro, MotionModelFromWindowMatchesConstantRate) {
  const Vec3 w0(0.5, -1.0, 2.0);
  GyroTrack g(linearGyro(w0, Vec3::Zero(), 0.0, 1.0, 0.001), Mat3::Identity(), 0.0);
  const GyroWindow w = g.window(0.4, 0.45);
  ASSERT_TRUE(w.ok());
  const MotionModel m = w.motionModel(0.42);
  const Mat3 expect = so3::exp(w0 * (0.45 - 0.42));
  EXPECT_LT((m.rotation(0.45) - expect).norm(), 1e-9);
}

TEST(IoGyro, StatusInsteadOfGuess) {
  GyroTrack empty({}, Mat3::Identity(), 0.0);
  EXPECT_EQ(empty.window(0.0, 0.1).status, GyroStatus::NoSamples);
  auto s = linearGyro(Vec3::Ones(), Vec3::Zero(), 1.0, 2.0, 0.005);
  GyroTrack g(s, Mat3::Identity(), 0.0);
  EXPECT_EQ(g.window(0.5, 0.6).status, GyroStatus::NotCovered);
  EXPECT_EQ(g.window(1.95, 2.1).status, GyroStatus::NotCovered);
  EXPECT_EQ(g.window(0.3, 0.2).status, GyroStatus::InvalidWindow);
  EXPECT_EQ(g.window(std::nan(""), 0.2).status, GyroStatus::InvalidWindow);
  EXPECT_EQ(toString(GyroStatus::NoSamples), "no_gyro");
  // a 50 ms hole
  std::vector<ImuSample> holed;
  for (const auto& x : s)
    if (x.t < 1.4 || x.t > 1.45) holed.push_back(x);
  GyroTrack h(holed, Mat3::Identity(), 0.0);
  EXPECT_EQ(h.window(1.3, 1.5).status, GyroStatus::Gap);
  EXPECT_TRUE(h.window(1.1, 1.3).ok());
}

TEST(IoGyroConformance, Davis240WindowAtRest) {
  const std::string p = celc::test::sharedData("aedat/davis240c_translation_boxes.aedat2");
  SKIP_IF_NO_SHARED(p);
  auto r = openEventSource(p);
  GyroTrack g(r->readImu(), Mat3::Identity(), 0.0);
  WindowOptions o;
  o.events_per_window = 20000;
  WindowSource ws(*r, o);
  EventWindow w;
  int ok = 0;
  while (ws.next(w)) {
    const GyroWindow gw = g.window(w.t0, w.t1);
    ok += gw.ok();
    EXPECT_LT(gw.mean_omega.norm(), 5.0);  // hand-held: well below 5 rad/s
  }
  EXPECT_EQ(ok, 8);  // every full window is covered
}

// Every event lies in exactly one window of fixed length without overlap,
// also events exactly on a boundary: with the origin at 0.000134 s and
// windows of 0.025 s, t0 + 0.025 rounds below the next window's start for
// some boundaries (0.150134 s among them), so t1 must be the next t0 itself.
TEST(IoWindow, TimeWindowsHoldEveryEventOnTheirBoundaries) {
  TempDir d;
  std::vector<Event> ev;
  for (int k = 0; k < 400; ++k) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6f", 0.000134 + k * 0.025);  // as a text file states it
    ev.push_back({std::strtod(text, nullptr), static_cast<float>(k % 200), 10.0f, true});
    ev.push_back({std::strtod(text, nullptr) + 0.0125, static_cast<float>(k % 200), 20.0f, false});
  }
  writeEventsText(d.file("e.txt"), ev);
  for (double seconds : {0.025, 0.05, 0.075}) {
    auto r = openEventSource(d.file("e.txt"));
    WindowOptions o;
    o.seconds_per_window = seconds;
    o.keep_partial = true;
    o.read_batch = 37;
    WindowSource ws(*r, o);
    EventWindow w;
    std::size_t total = 0;
    while (ws.next(w)) {
      for (const Event& e : w.events) {
        EXPECT_GE(e.t, w.t0);
        EXPECT_LT(e.t, w.t1);
      }
      total += w.events.size();
    }
    EXPECT_EQ(total, ev.size()) << seconds << " s windows";
  }
}

// A window that would hold more than windows.max_events events (a burst of
// events at one time, as in an AEDAT 4 file of packets of 4,000,000 events
// sharing a timestamp) is an error naming its time, read with a buffer of at
// most max_events + read_batch events, not gigabytes.
TEST(IoWindow, WindowOverMaxEventsIsAnErrorNamingItsTime) {
  TempDir d;
  std::vector<Event> ev{{0.0, 1.0f, 1.0f, true}};
  for (int i = 0; i < 3000; ++i) ev.push_back({0.01, static_cast<float>(i % 200), 5.0f, true});
  ev.push_back({0.1, 2.0f, 2.0f, false});
  writeEventsText(d.file("burst.txt"), ev);
  auto r = openEventSource(d.file("burst.txt"));
  WindowOptions o;
  o.seconds_per_window = 0.025;
  o.max_events = 1000;
  o.read_batch = 100;
  WindowSource ws(*r, o);
  EventWindow w;
  try {
    ws.next(w);
    ADD_FAILURE() << "no error for a window of 3001 events";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("burst.txt: the window [0.000000, 0.025000) s holds more than windows.max_events = 1000"),
              std::string::npos)
        << what;
  }
  EXPECT_LE(ws.peakBuffered(), 1000u + 2 * 100u);
  // Windows by count cannot ask for more than the bound.
  WindowOptions count;
  count.events_per_window = 2000;
  count.max_events = 1000;
  EXPECT_NE(count.validate().find("events: 2000 per window, more than max_events = 1000"), std::string::npos);
}

// ---- malformed and hostile inputs (docs/robustness.md's table) -------------------

// ---- endless windowing across an outlier ----------------------------------------

TEST(IoRobustness, OutlierTimestampInTextDoesNotMakeEndlessWindows) {
  TempDir d;
  for (const char* outlier : {"10000000", "1e300"}) {
    std::string text;
    for (int i = 0; i < 2000; ++i) {
      char line[64];
      std::snprintf(line, sizeof line, "%.6f %d %d 1\n", 1.0 + i * 1e-3, i % 240, i % 180);
      text += line;
      if (i == 700) text += std::string(outlier) + " 5 5 1\n";
    }
    writeBytes(d.file("e.txt"), text);
    auto r = openEventSource(d.file("e.txt"));
    WindowOptions w;
    w.seconds_per_window = 0.1;
    WindowSource src(*r, w);
    EventWindow win;
    std::size_t n = 0;
    const auto start = std::chrono::steady_clock::now();
    while (src.next(win) && n < 1000) ++n;
    EXPECT_LT(n, 25u) << outlier;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    EXPECT_EQ(r->warnings().time_jumps, 1u) << outlier;
    EXPECT_NE(r->warnings().messages.at(0).find("line 702"), std::string::npos) << r->warnings().messages.at(0);
  }
}

TEST(IoRobustness, WindowSourceSkipsLongGapsAndRefusesUnrepresentableTimes) {
  TempDir d;
  // a real gap (two events confirm it): kept by the reader, skipped by the windows
  writeBytes(d.file("g.txt"), "1.0 1 1 1\n1.05 1 1 1\n1.25 1 1 1\n5000.0 2 2 1\n5000.01 2 2 1\n5000.2 2 2 1\n");
  auto r = openEventSource(d.file("g.txt"));
  WindowOptions w;
  w.seconds_per_window = 0.1;
  WindowSource src(*r, w);
  EventWindow win;
  std::vector<EventWindow> got;
  while (src.next(win) && got.size() < 100) got.push_back(win);
  // 1.0-1.3 s: three windows, then the window holding 5000.0 (the grid's rounding
  // near 5000 s may put it one window earlier) and the one holding 5000.01
  ASSERT_GE(got.size(), 4u);
  ASSERT_LE(got.size(), 5u);
  EXPECT_EQ(got[1].events.size(), 0u);  // a gap of one window is returned empty, as before
  EXPECT_EQ(got[2].events.size(), 1u);
  EXPECT_GT(got[3].t0, 4999.8);
  EXPECT_LE(got[3].t0, 5000.0);
  EXPECT_GT(got.back().t1, 5000.01);
  EXPECT_EQ(src.gaps(), 1u);
  EXPECT_GT(src.skippedWindows(), 40000u);
  ASSERT_EQ(src.reports().size(), 1u);
  EXPECT_NE(src.reports()[0].find("g.txt: no events in"), std::string::npos) << src.reports()[0];
  EXPECT_EQ(r->warnings().time_jumps, 1u);  // the reader reports the gap too
  // a gap to 1e300: the window grid restarts there and t0 + S == t0 is an error, not a loop
  writeBytes(d.file("h.txt"), "1.0 1 1 1\n1.2 1 1 1\n1e300 2 2 1\n1e300 2 2 1\n");
  auto r2 = openEventSource(d.file("h.txt"));
  WindowSource src2(*r2, w);
  std::size_t n = 0;
  EXPECT_IO_ERROR(
      while (src2.next(win) && n < 100) ++n, "h.txt", "too large for windows");
  EXPECT_LT(n, 100u);
}
