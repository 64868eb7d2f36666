// End to end against rendered ground truth: `celc synth` renders a sequence,
// `celc run` estimates the velocity per window, and the estimates are compared
// with the simulator's twist (docs/synth.md, "End-to-end accuracy").
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "celc/eval/run_tables.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace celc;

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

// Rendered pure rotation (issue 13): the sample's room seen by a camera that
// only turns, at 1.6 rad/s, for 0.6 s. With the default windows and with
// fixed windows of 0.2 s and of 80,000 events, no row is `ok` with a
// sigma_deg below 10 deg (measured: every window degenerate, no_parallax).
TEST(EndToEnd, RenderedPureRotationIsNeverConfident) {
  const fs::path d = test::freshTempDir("e2e_rotation");
  std::ifstream in(CELC_SOURCE_DIR "/config/scenes/sample_davis346_room.yaml");
  std::string scene((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto replaceLine = [&](const std::string& key, const std::string& line) {
    const auto at = scene.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    scene.replace(at, scene.find('\n', at) - at, line);
  };
  replaceLine("duration:", "duration: 0.6");
  replaceLine("  v: [", "  v: [0.0, 0.0, 0.0]");
  replaceLine("  w: [", "  w: [0.6, -1.2, 0.9]");
  std::ofstream((d / "scene.yaml").string()) << scene;
  const auto synth = test::runCelc("synth '" + (d / "scene.yaml").string() + "' -o '" + (d / "seq").string() + "' -q", d);
  ASSERT_EQ(synth.status, 0) << synth.err;
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
