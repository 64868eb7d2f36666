// End to end against rendered ground truth: `celc synth` renders a sequence,
// `celc run` estimates the velocity per window, and the estimates are compared
// with the simulator's twist (docs/simulation.md, "End-to-end accuracy").
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/eval/run_tables.hpp"
#include "celc/solver/methods.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace celc;

namespace {
/// A scene file of the repository with lines replaced: each key (the start
/// of a line) gets the whole given line.
std::string editedScene(const std::string& file, const std::vector<std::pair<std::string, std::string>>& lines) {
  std::ifstream in(std::string(CELC_SOURCE_DIR "/config/scenes/") + file);
  std::string scene((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const auto& [key, line] : lines) {
    const auto at = scene.find(key);
    if (at == std::string::npos) return "";
    scene.replace(at, scene.find('\n', at) - at, line);
  }
  return scene;
}

/// The edited scene written into d and rendered into d/seq by `celc synth`;
/// returns the error, empty when it worked.
std::string renderEditedScene(const fs::path& d, const std::string& file,
                              const std::vector<std::pair<std::string, std::string>>& lines) {
  const std::string scene = editedScene(file, lines);
  if (scene.empty()) return file + ": a line to replace is missing";
  std::ofstream((d / "scene.yaml").string()) << scene;
  const auto synth = test::runCelc("synth '" + (d / "scene.yaml").string() + "' -o '" + (d / "seq").string() + "' -q", d);
  return synth.status == 0 ? "" : synth.err;
}

/// The 4 m/s room (e2e_davis346_room_fast.yaml) with `lines` edited, rendered
/// into d and run with `celc run ... ARGS --threads 2 -q`: window 0's ok rows
/// (none, with a test failure, when a step failed).
std::vector<WindowsCsvRow> firstWindowOfEditedRoom(const fs::path& d,
                                                   const std::vector<std::pair<std::string, std::string>>& lines,
                                                   const std::string& args) {
  const std::string rendered = renderEditedScene(d, "e2e_davis346_room_fast.yaml", lines);
  EXPECT_EQ(rendered, "");
  if (!rendered.empty()) return {};
  const auto run = test::runCelc(
      "run '" + (d / "seq").string() + "' " + args + " --threads 2 -q -o '" + (d / "run").string() + "'", d);
  EXPECT_EQ(run.status, 0) << run.err;
  std::vector<WindowsCsvRow> out;
  if (run.status != 0) return out;
  for (const auto& row : readWindowsCsv((d / "run" / "windows.csv").string(), false))
    if (row.window == 0 && row.status == "ok") out.push_back(row);
  return out;
}
}  // namespace

// The stated setting (config/scenes/e2e_davis346_room_fast.yaml): a DAVIS346
// crossing a room of three textured planes 1-2.5 m away at 4 m/s with a slow
// rotation; 0.1 s windows (0.4 m of translation, 16-40% of the depth),
// gyroscope from the simulated IMU, clusters and lines from the events.
// Measured: celc_ml median phi 0.023 rad here (0.009 and 0.012 rad with scene
// seeds 2 and 3); 0.05 rad leaves a factor of two. The pipeline's ground
// truth, differentiated from the 200 Hz pose file, must equal the simulated
// twist (constant, so the same in every window).
TEST(EndToEnd, RenderedRoomVelocityWithinTolerance) {
  const fs::path d = test::freshTempDir("e2e_room");
  const std::string scene = CELC_SOURCE_DIR "/config/scenes/e2e_davis346_room_fast.yaml";
  const auto synth = test::runCelc("synth '" + scene + "' -o '" + (d / "seq").string() + "' -q", d);
  ASSERT_EQ(synth.status, 0) << synth.err;
  const auto run = test::runCelc("run '" + (d / "seq").string() + "' -c '" CELC_SOURCE_DIR
                                 "/config/run.yaml' --window-seconds 0.1 --threads 2 -q -o '" +
                                     (d / "run").string() + "'",
                                 d);
  ASSERT_EQ(run.status, 0) << run.err;
  const auto rows = readWindowsCsv((d / "run" / "windows.csv").string(), false);
  const Vec3 twist = Vec3(3.2, -0.6, 2.4).normalized();  // the scene's v
  int windows = 0;
  for (const auto& row : rows) {
    ASSERT_TRUE(row.has_gt) << "window " << row.window;
    EXPECT_LT((row.gt - twist).norm(), 1e-3) << "window " << row.window;
    if (row.method == "celc_ml") ++windows;
  }
  EXPECT_EQ(windows, 4);
  for (const auto& s : summarize(rows)) {
    if (s.method != "celc_ml") continue;
    EXPECT_EQ(s.ok, 4);
    EXPECT_LE(s.phi_median, 0.05) << "celc_ml median phi [rad]";
  }
  fs::remove_all(d);
}

// The parallax policy on a dense recording: the room turning at 1.7 rad/s
// while it moves at 2 m/s gives 110-170k events per 0.05 s. D measured on
// every k-th event (30,000 of them) found no cluster on windows of 0.15 s and
// longer, and the windows grew to max_seconds (0.3 s, 70-108 px of
// translation; celc_ml 0.65 rad off in one of them). The probe now repeats
// on a denser subset: measured, the windows are 0.125-0.15 s with D >= 25 px.
TEST(EndToEnd, DenseRecordingGetsWindowsShorterThanTheMaximum) {
  const fs::path d = test::freshTempDir("e2e_dense");
  std::ifstream in(CELC_SOURCE_DIR "/config/scenes/e2e_davis346_room_fast.yaml");
  std::string scene((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = scene.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    scene.replace(at, from.size(), to);
  };
  replace("seed: 1", "seed: 106");
  replace("duration: 0.41", "duration: 0.32");
  replace("v: [3.2, -0.6, 2.4]", "v: [-1.1, 1.71, 0.01]");
  replace("w: [0.1, -0.25, 0.15]", "w: [-0.09, 1.71, -0.3]");
  std::ofstream((d / "scene.yaml").string()) << scene;
  const auto synth = test::runCelc("synth '" + (d / "scene.yaml").string() + "' -o '" + (d / "seq").string() + "' -q", d);
  ASSERT_EQ(synth.status, 0) << synth.err;
  const auto run = test::runCelc("run '" + (d / "seq").string() + "' --methods celc --threads 2 -q -o '" +
                                     (d / "run").string() + "'",
                                 d);
  ASSERT_EQ(run.status, 0) << run.err;
  const auto rows = readWindowsCsv((d / "run" / "windows.csv").string(), false);
  ASSERT_GE(rows.size(), 2u);
  for (const auto& row : rows) {
    if (row.t_end > 0.3) continue;  // the last window, cut by the data
    EXPECT_LT(row.t_end - row.t_start, 0.25) << "window " << row.window;
    EXPECT_GE(row.translation_px, 15.0) << "window " << row.window;
  }
  fs::remove_all(d);
}

// The last window, cut by the end of the data. The sample's room for 0.29 s:
// two windows of 0.125 s (their probes measured D >= 25 px), then 0.04 s.
// - With the defaults that rest, shorter than the window before it, is
//   joined to it: two windows, both solved (the second 0.175 s long: its
//   last step of 0.025 s is cut by the data at 0.29 s).
// - Where the longest window has no room for it (max_seconds 0.125 s) it is
//   a window of its own, and the parallax policy's verdict reaches it: its D,
//   measured on the whole window, is 8.7 px, below windows.no_parallax_px
//   set to 10 here, so every method is `degenerate / no_parallax` there, as
//   at max_seconds. (At the default, 3 px, it is solved: celc_ml 0.08 rad
//   off at sigma_deg 10.9, celc 1.46 rad at 83 deg.)
TEST(EndToEnd, ShortLastWindowIsJoinedOrWithoutParallaxNotSolved) {
  const fs::path d = test::freshTempDir("e2e_last_window");
  ASSERT_EQ(renderEditedScene(d, "sample_davis346_room.yaml", {{"duration:", "duration: 0.29"}}), "");
  auto runRows = [&](const std::string& extra) {
    const auto run = test::runCelc("run '" + (d / "seq").string() + "' --threads 2 -q --force -o '" +
                                       (d / "run").string() + "'" + extra,
                                   d);
    EXPECT_EQ(run.status, 0) << run.err;
    return readWindowsCsv((d / "run" / "windows.csv").string(), false);
  };
  auto rows = runRows("");
  ASSERT_EQ(rows.size(), 2 * runMethods().size());  // two windows
  for (const auto& row : rows) {
    EXPECT_EQ(row.status, "ok") << row.method << " window " << row.window;
    // The joined window runs past the ground truth's last pose (0.29 s): its
    // truth is the mean over the span its events cover.
    EXPECT_TRUE(row.has_gt && row.has_metrics) << row.method << " window " << row.window;
    if (row.window == 1) {
      EXPECT_NEAR(row.t_end - row.t_start, 0.175, 1e-6) << row.method;
    }
  }
  rows = runRows(" --set windows.max_seconds=0.125 --set windows.slow_turn_max_seconds=0.125 --set windows.no_parallax_px=10");
  ASSERT_FALSE(rows.empty());
  const std::int64_t last = rows.back().window;
  int last_rows = 0, ok_before = 0;
  for (const auto& row : rows) {
    if (row.window != last) {
      ok_before += row.status == "ok";
      continue;
    }
    ++last_rows;
    EXPECT_LT(row.t_end - row.t_start, 0.1) << row.method;
    EXPECT_LT(row.translation_px, 10.0) << row.method;
    EXPECT_EQ(row.status, "degenerate") << row.method;
    EXPECT_EQ(row.reason, "no_parallax") << row.method;
  }
  EXPECT_EQ(last_rows, static_cast<int>(runMethods().size()));
  EXPECT_GE(ok_before, 8);  // both earlier windows, celc_ml and celc_opt among them
  fs::remove_all(d);
}

// A slowly turning camera far from its scene (config/scenes/slow_deep.yaml:
// 1 m/s at 3-6 m, 0.2 rad/s) for 1.05 s: its lines show ~5 px per 0.3 s, so
// with windows of at most max_seconds (0.3 s) every window is `no_parallax`.
// The window grows on while the camera turns less than slow_turn_rad (0.5
// rad): to 1 s (slow_turn_max_seconds), where D is ~22 px and celc_ml is
// 0.009 rad off (measured; 0.1 rad is the D study's tolerance at 15-25 px).
// With the extension off (slow_turn_max_seconds = max_seconds, both 0.2 s
// here) the first window stops at 0.2 s with D 4.3 px, `no_parallax` below
// a no_parallax_px of 7 px.
TEST(EndToEnd, SlowlyTurningCameraGetsWindowsLongerThanMaxSeconds) {
  const fs::path d = test::freshTempDir("e2e_slow_turn");
  ASSERT_EQ(renderEditedScene(d, "slow_deep.yaml", {{"duration:", "duration: 1.05"}}), "");
  auto firstWindow = [&](const std::string& extra) {
    const fs::path out = d / ("run" + std::to_string(extra.size()));
    const auto run = test::runCelc("run '" + (d / "seq").string() + "' --methods celc_ml --threads 2 -q " + extra +
                                       " -o '" + out.string() + "'",
                                   d);
    EXPECT_EQ(run.status, 0) << run.err;
    const auto rows = readWindowsCsv((out / "windows.csv").string(), false);
    return rows.empty() ? WindowsCsvRow{} : rows.front();
  };
  const auto grown = firstWindow("");
  EXPECT_NEAR(grown.t_end - grown.t_start, 1.0, 1e-6);
  EXPECT_EQ(grown.status, "ok") << grown.reason;
  EXPECT_GE(grown.translation_px, 15.0);
  EXPECT_LT(grown.phi, 0.1);
  const auto capped = firstWindow(
      "--set windows.max_seconds=0.2 --set windows.slow_turn_max_seconds=0.2 --set windows.no_parallax_px=7");
  EXPECT_NEAR(capped.t_end - capped.t_start, 0.2, 1e-6);
  EXPECT_LT(capped.translation_px, 7.0);
  EXPECT_EQ(capped.reason, "no_parallax");
  fs::remove_all(d);
}

// The linear stage's Tukey stage (solver.linear.tukey_k, 3 in `celc run`).
// A held-out room (`heldout_scenes.py --seed 7000`, its first scene: 1.5
// m/s, 0.98 rad/s, 1 Hz/px of noise) cut to 0.45 s, two windows of 0.225 s:
// in the second, clusters at the chessboard's corners hold 5-20% of another
// edge's events a few pixels from their line. Huber's weights keep a bounded pull from each of those rows and
// celc is 0.09-0.20 rad off over seeds 1-4; with Tukey's biweight from the
// Huber end point, 0.010-0.034 (measured). celc_opt's last refinement under
// Tukey's biweight (solver.refine.tukey_scale 3) instead of the Cauchy loss:
// 0.055-0.083 against 0.111-0.158 rad (seed 1, the test's: 0.057 / 0.154).
// celc's part pins the linear stage's 1000 rows (`celc run`'s default): on
// 4000 this window is 0.07-0.14 rad off with the Tukey stage and 0.28-0.33
// without (celc_opt does not move).
// The clusters are grown at a fixed 20 deg (cluster.smoothness_noise_factor
// 0), at 3x the median speed (cluster.c_speed_factor 3), neither cut to their
// moving lines (cluster.line_split_px 0) nor redrawn under the motion
// (cluster.motion_reassign_px 0; redrawn, celc is 0.018 and celc_opt 0.004
// rad off without either stage), which leaves these impure
// clusters; the defaults give this window purer clusters, where
// the stage matters less (with the noise angle: celc 0.079, celc_opt
// 0.036 rad).
TEST(EndToEnd, TukeyStageKeepsCelcOnTrackWithImpureClusters) {
  const fs::path d = test::freshTempDir("e2e_tukey");
  ASSERT_EQ(renderEditedScene(d, "e2e_davis346_room_fast.yaml",
                              {{"seed:", "seed: 1000"},
                               {"duration:", "duration: 0.45"},
                               {"  v: [", "  v: [0.22, 1.2, -0.88]"},
                               {"  w: [", "  w: [-0.54, 0.14, -0.81]"},
                               {"  noise_rate:", "  noise_rate: 1.0"}}),
            "");
  auto secondWindowPhi = [&](const std::string& method, const std::string& extra) {
    const fs::path out = d / ("run" + method + std::to_string(extra.size()));
    const auto run = test::runCelc("run '" + (d / "seq").string() + "' --window-seconds 0.225 --methods " + method +
                                       " --threads 2 -q --set cluster.smoothness_noise_factor=0 "
                                       "--set cluster.c_speed_factor=3 --set cluster.line_split_px=0 "
                                       "--set cluster.motion_reassign_px=0 " + extra +
                                       " -o '" + out.string() + "'",
                                   d);
    EXPECT_EQ(run.status, 0) << run.err;
    const auto rows = readWindowsCsv((out / "windows.csv").string(), false);
    EXPECT_EQ(rows.size(), 2u);
    return rows.size() == 2 && rows[1].status == "ok" ? rows[1].phi : NAN;
  };
  EXPECT_LT(secondWindowPhi("celc", "--set solver.linear.max_rows=1000"), 0.05);
  EXPECT_GT(secondWindowPhi("celc", "--set solver.linear.max_rows=1000 --set solver.linear.tukey_k=0"), 0.08);
  EXPECT_LT(secondWindowPhi("celc_opt", ""), 0.09);
  EXPECT_GT(secondWindowPhi("celc_opt", "--set solver.refine.tukey_scale=0"), 0.11);
  fs::remove_all(d);
}

// Rendered pure rotation: the sample's room seen by a camera that
// only turns, at 1.6 rad/s, for 0.6 s. With the default windows and with
// fixed windows of 0.2 s and of 80,000 events, no row is `ok` with a
// sigma_deg below 10 deg (measured: every window degenerate, no_parallax).
TEST(EndToEnd, RenderedPureRotationIsNeverConfident) {
  const fs::path d = test::freshTempDir("e2e_rotation");
  ASSERT_EQ(renderEditedScene(d, "sample_davis346_room.yaml", {{"duration:", "duration: 0.6"},
                                                                      {"  v: [", "  v: [0.0, 0.0, 0.0]"},
                                                                      {"  w: [", "  w: [0.6, -1.2, 0.9]"}}), "");
  int rows_seen = 0;
  for (const std::string windows : {"", "--window-seconds 0.2", "--window-events 80000"}) {
    const fs::path out = d / ("run" + std::to_string(rows_seen));
    const auto run = test::runCelc("run '" + (d / "seq").string() + "' " + windows + " --threads 2 -q -o '" +
                                       out.string() + "'",
                                   d);
    ASSERT_EQ(run.status, 0) << run.err;
    const auto rows = readWindowsCsv((out / "windows.csv").string(), false);
    ASSERT_FALSE(rows.empty()) << windows;
    for (const auto& row : rows)
      EXPECT_FALSE(row.status == "ok" && row.sigma_deg < 10.0)
          << windows << " window " << row.window << " " << row.method << " sigma " << row.sigma_deg;
    rows_seen += static_cast<int>(rows.size());
  }
  EXPECT_GE(rows_seen, 15);
  fs::remove_all(d);
}


// The clusters' purity on the shipped chessboard (0.25 s: 144,000 events;
// every grid line a run of squares' edges of alternating polarity). With c
// at the median normal speed (cluster.c_speed_factor 1) and the growing's
// fixed 20 deg, clusters ran through the corners from one grid line into the
// next: 61% of the clustered events were in the majority line of their
// cluster (renderer's labels), and celc_ml on those clusters was 1.13 rad
// off; at 3x the median speed 98%. The smoothness angle from the normals'
// noise (cluster.smoothness_noise_factor) keeps the lines apart by itself at
// the default factor 1 (docs/clustering.md).
TEST(EndToEnd, RenderedChessboardClustersArePure) {
  const fs::path d = test::freshTempDir("e2e_chessboard");
  ASSERT_EQ(renderEditedScene(d, "davis346_chessboard.yaml", {{"duration:", "duration: 0.25"}}), "");
  std::ifstream ev((d / "seq" / "events.txt").string()), lab((d / "seq" / "labels.txt").string());
  std::vector<Event> events;
  std::vector<int> labels;
  double t;
  int x, y, p, l;
  while (ev >> t >> x >> y >> p && lab >> l) {
    events.push_back({t, static_cast<float>(x), static_cast<float>(y), p != 0});
    labels.push_back(l);
  }
  ASSERT_GT(events.size(), 100000u);
  auto purity = [&](double factor, double noise_factor) {
    ClusterOptions options;
    options.c_speed_factor = factor;
    options.smoothness_noise_factor = noise_factor;
    const ClusterResult r = clusterEvents(events, options);
    std::map<int, std::map<int, int>> counts;  // cluster -> true line -> events
    for (size_t i = 0; i < events.size(); ++i)
      if (r.labels[i] >= 0) ++counts[r.labels[i]][labels[i]];
    long clustered = 0, in_majority = 0;
    for (const auto& [cluster, lines] : counts) {
      int most = 0;
      for (const auto& [line, n] : lines) {
        clustered += n;
        if (line >= 0) most = std::max(most, n);
      }
      in_majority += most;
    }
    return clustered > 0 ? static_cast<double>(in_majority) / clustered : 0.0;
  };
  const ClusterOptions defaults;
  ASSERT_EQ(defaults.c_speed_factor, 1.0);
  // The smoothness angle from the normals' noise (about 3-9 deg on rendered
  // events) keeps the grid lines apart (measured: 0.997) ...
  EXPECT_GE(purity(defaults.c_speed_factor, defaults.smoothness_noise_factor), 0.95);
  EXPECT_LE(purity(1.0, 0.0), 0.8);  // ... which a fixed 20 deg does not
  EXPECT_GE(purity(3.0, 0.0), 0.95);  // the former remedy, 3x the median speed
  fs::remove_all(d);
}

// The sign from cheirality (solver/sign.hpp), each cluster's vote weighted by
// its line's rotation-free motion: a room approached at 2.45 m/s (mostly
// downward and forward) turning at 0.9 rad/s, 0.15 s windows. There about 80
// small clusters whose lines moved 0.1-3 px voted against the 20 large ones
// that moved 8-52 px; one vote per cluster gave every method the reversed
// direction in the first window (celc_ml 3.13 rad, 0.008 rad from -v).
TEST(EndToEnd, ClustersThatHardlyMovedDoNotDecideTheSign) {
  const fs::path d = test::freshTempDir("e2e_sign");
  const auto rows = firstWindowOfEditedRoom(d,
                                            {{"seed:", "seed: 1009"},
                                             {"duration:", "duration: 0.31"},
                                             {"  v: [", "  v: [-0.28, 1.9, 1.53]"},
                                             {"  w: [", "  w: [-0.79, -0.37, 0.24]"},
                                             {"  noise_rate:", "  noise_rate: 1.0"}},
                                            "--window-seconds 0.15 --methods celc,celc_ml");
  for (const auto& row : rows) EXPECT_LT(row.phi, 0.1) << row.method;
  EXPECT_EQ(rows.size(), 2u);
  fs::remove_all(d);
}

// ... and by the share of the window its lines span: a room left backwards at
// 1.17 m/s while turning at 1.48 rad/s (held-out draw 9000's h04_room), one
// 0.325 s window. Of its 408 clusters 376 have lines less than 0.02 s apart;
// their lines moved 1-3 px, mostly by the fits' and the rotation's errors,
// and 93% of them voted for -v. Weighted by motion alone they outvoted the 19
// clusters spanning most of the window (every one right): celc, celc_opt and
// celc_ml were 2.94-3.12 rad off (their axes 1.5-11 deg from the truth).
// Rendered here for 0.33 s only, the window gave 2.53 / 3.11 / 3.09 rad
// before and gives 0.62 / 0.03 / 0.05 (celc's axis is 35 deg off: only its
// sign is checked).
TEST(EndToEnd, ClustersSeenBrieflyDoNotDecideTheSign) {
  const fs::path d = test::freshTempDir("e2e_sign_brief");
  const auto rows = firstWindowOfEditedRoom(d,
                                            {{"seed:", "seed: 1004"},
                                             {"duration:", "duration: 0.33"},
                                             {"  v: [", "  v: [0.0, -0.36, -1.11]"},
                                             {"  w: [", "  w: [1.41, 0.46, 0.02]"},
                                             {"  noise_rate:", "  noise_rate: 2.0"}},
                                            "--window-seconds 0.325 --methods celc,celc_opt,celc_ml");
  for (const auto& row : rows) EXPECT_LT(row.phi, row.method == "celc" ? M_PI / 2 : 0.1) << row.method;
  EXPECT_EQ(rows.size(), 3u);
  fs::remove_all(d);
}

// Answers in front of the camera (MlOptions::cheiral_min and
// UncertaintyOptions::cheiral_min), on the shipped hand-held scene
// (config/scenes/handheld_fast_rotation.yaml, three windows), with clusters
// not cut to their moving lines (cluster.line_split_px 0: cut, the first
// window's answers are 0.67 rad off, the constant-velocity bias, and all
// three get the floor). Measured with both off: the third window's lowest joint cost lies 0.17 rad from the
// truth where only part of the clusters' weighted votes put the lines in
// front of the camera; a unanimous basin 0.026 rad off costs a little more,
// and celc_ml takes it with the option. celc's answer there (0.14 rad off)
// has sigma_deg 6.3 without the floor and 61.2 with it, its votes split.
// The first window's answers are unanimous: the options leave them alone.
TEST(EndToEnd, AnswersLieInFrontOfTheCamera) {
  const fs::path d = test::freshTempDir("e2e_cheiral");
  const auto synth = test::runCelc(
      "synth '" CELC_SOURCE_DIR "/config/scenes/handheld_fast_rotation.yaml' -o '" + (d / "seq").string() + "' -q",
      d);
  ASSERT_EQ(synth.status, 0) << synth.err;
  auto celcMl = [&](const std::string& extra) {
    const fs::path out = d / ("run" + std::to_string(extra.size()));
    const auto run = test::runCelc("run '" + (d / "seq").string() +
                                       "' --methods celc,celc_opt,celc_ml --threads 2 -q --set cluster.line_split_px=0 " +
                                       extra + " -o '" + out.string() + "'",
                                   d);
    EXPECT_EQ(run.status, 0) << run.err;
    std::map<std::pair<std::int64_t, std::string>, WindowsCsvRow> rows;
    for (const auto& row : readWindowsCsv((out / "windows.csv").string(), false)) rows[{row.window, row.method}] = row;
    EXPECT_EQ(rows.size(), 9u);
    return rows;
  };
  auto off = celcMl("--set solver.ml.cheiral_min=0 --set solver.uncertainty.cheiral_min=0");
  auto on = celcMl("");
  ASSERT_EQ(off.size(), 9u);
  ASSERT_EQ(on.size(), 9u);
  auto row = [](auto& rows, std::int64_t window, const std::string& method) -> const WindowsCsvRow& {
    return rows[std::make_pair(window, method)];
  };
  ASSERT_EQ(row(off, 2, "celc_ml").status, "ok");
  ASSERT_EQ(row(on, 2, "celc_ml").status, "ok");
  EXPECT_GT(row(off, 2, "celc_ml").phi, 0.1);
  EXPECT_LT(row(on, 2, "celc_ml").phi, 0.05);
  EXPECT_GT(row(off, 2, "celc").phi, 0.1);
  EXPECT_LT(row(off, 2, "celc").sigma_deg, 10.0);
  EXPECT_GE(row(on, 2, "celc").sigma_deg, 61.2);
  for (const std::string method : {"celc", "celc_opt", "celc_ml"}) {
    ASSERT_EQ(row(on, 0, method).status, "ok") << method;
    EXPECT_NEAR(row(on, 0, method).phi, row(off, 0, method).phi, 1e-9) << method;
    EXPECT_NEAR(row(on, 0, method).sigma_deg, row(off, 0, method).sigma_deg, 1e-9) << method;
  }
  fs::remove_all(d);
}

// A redraw under the motion that gives again the clusters of the redraw kept
// before it is not solved again (`celc run -vv` logs "unchanged, not kept"):
// it would give the same observations, answer and cost. On the 4 m/s room
// three of five windows end so after one kept round (measured), and their
// rows are those of a run that stops after one round.
TEST(EndToEnd, RedrawThatGivesTheKeptClustersAgainEndsTheRounds) {
  const fs::path d = test::freshTempDir("e2e_redraw_unchanged");
  const auto synth = test::runCelc(
      "synth '" CELC_SOURCE_DIR "/config/scenes/e2e_davis346_room_fast.yaml' -o '" + (d / "seq").string() + "' -q", d);
  ASSERT_EQ(synth.status, 0) << synth.err;
  auto run = [&](const std::string& name, const std::string& extra) {
    const auto r = test::runCelc("run '" + (d / "seq").string() + "' --methods celc_ml --threads 2 --no-plots -vv " +
                                     extra + " -o '" + (d / name).string() + "'",
                                 d);
    EXPECT_EQ(r.status, 0) << r.err;
    return r.err;
  };
  const std::string log = run("three", "");
  run("one", "--set cluster.motion_redraw_rounds=1");
  // Each window's redraw outcomes in order: 'k' kept, 'n' not kept, 'u' unchanged.
  std::map<std::int64_t, std::string> rounds;
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);) {
    const auto at = line.find("debug window ");
    if (at == std::string::npos || line.find("clusters under the motion") == std::string::npos) continue;
    const std::int64_t window = std::stoll(line.substr(at + 13));
    rounds[window] += line.find("unchanged, not kept") != std::string::npos ? 'u'
                      : line.find(": not kept") != std::string::npos    ? 'n'
                                                                          : 'k';
  }
  std::map<std::int64_t, WindowsCsvRow> three, one;
  for (const auto& row : readWindowsCsv((d / "three" / "windows.csv").string(), false)) three[row.window] = row;
  for (const auto& row : readWindowsCsv((d / "one" / "windows.csv").string(), false)) one[row.window] = row;
  int ended_unchanged = 0;
  for (const auto& [window, outcomes] : rounds) {
    const auto u = outcomes.find('u');
    if (u == std::string::npos) continue;
    EXPECT_EQ(u, outcomes.size() - 1) << "window " << window << ": " << outcomes;  // it ends the rounds
    EXPECT_GT(u, 0u) << "window " << window << ": only after a kept redraw";
    if (outcomes != "ku") continue;
    ++ended_unchanged;
    ASSERT_TRUE(three.count(window) && one.count(window)) << "window " << window;
    EXPECT_EQ(three[window].v, one[window].v) << "window " << window;
    EXPECT_EQ(three[window].sigma_deg, one[window].sigma_deg) << "window " << window;
    EXPECT_EQ(three[window].n_clusters, one[window].n_clusters) << "window " << window;
  }
  EXPECT_GE(ended_unchanged, 2);
  fs::remove_all(d);
}
