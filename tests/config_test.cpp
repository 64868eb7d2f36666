// The YAML configuration: defaults, round trip, and errors that name the key and line.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "celc/config/config.hpp"
#include "celc/io/calibration.hpp"
#include "celc/pipeline/batch.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/render_sequence.hpp"
#include "io_test_util.hpp"

using namespace celc;
using celc::test::readBytes;
using celc::test::TempDir;
using celc::test::writeBytes;

TEST(Config, ShippedFileEqualsDefaults) {
  const auto cfg = loadSimulateConfig(CELC_SOURCE_DIR "/config/simulate.yaml");
  const SimulateConfig def;
  EXPECT_EQ(toYaml(cfg), toYaml(def));
}

TEST(Config, EffectiveConfigRoundTrips) {
  SimulateConfig c;
  c.scene.n_lines = 7;
  c.scene.velocity = Vec3(0.1, -0.2, 0.3);
  c.scene.motion = MotionModelKind::GyroIntegrated;
  c.solver.linear.max_rows = 321;
  c.solver.refine.huber_px = 0.75;
  c.methods = {Method::Ce3lc, Method::Celc};
  c.trials = 9;
  const auto back = parseSimulateConfig(toYaml(c), "roundtrip");
  EXPECT_EQ(toYaml(back), toYaml(c));
  EXPECT_EQ(back.scene.n_lines, 7);
  EXPECT_EQ(back.solver.linear.max_rows, 321);
}

TEST(Config, UnknownKeyNamesKeyAndLine) {
  try {
    parseSimulateConfig("scene:\n  n_lines: 4\n  n_line: 5\n", "my.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("my.yaml:3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("scene.n_line"), std::string::npos) << msg;
  }
}

TEST(Config, WrongTypeNamesKey) {
  try {
    parseSimulateConfig("solver:\n  linear:\n    max_rows: many\n", "c.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("c.yaml:3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("solver.linear.max_rows"), std::string::npos) << msg;
    EXPECT_NE(msg.find("integer"), std::string::npos) << msg;
  }
  EXPECT_THROW(parseSimulateConfig("scene:\n  velocity: [1, 2]\n", "v.yaml"), ConfigError);
  EXPECT_THROW(parseSimulateConfig("scene: [1, 2]\n", "s.yaml"), ConfigError);
  EXPECT_THROW(parseSimulateConfig("study:\n  methods: [celc, magic]\n", "m.yaml"), ConfigError);
}

TEST(Config, InvalidValuesAndSyntax) {
  EXPECT_THROW(parseSimulateConfig("scene:\n  duration: -1\n", "d.yaml"), ConfigError);
  EXPECT_THROW(parseSimulateConfig("scene:\n  z_range: [-1, 2]\n", "z.yaml"), ConfigError);
  EXPECT_THROW(parseSimulateConfig("solver:\n  refine:\n    huber_px: 0\n", "h.yaml"), ConfigError);
  EXPECT_THROW(parseSimulateConfig("scene: {n_lines: [\n", "syntax.yaml"), ConfigError);
  EXPECT_THROW(loadSimulateConfig("/nonexistent/celc.yaml"), ConfigError);
}

// ---- YAML files of every kind ---------------------------------------------------

// ---- YAML: a key or section given twice names both lines ------------------------

TEST(IoRobustness, DuplicatedSectionsInCalibrationSceneAndBatchNameBothLines) {
  TempDir d;
  auto configError = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const ConfigError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no ConfigError";
    return {};
  };
  writeBytes(d.file("c.yaml"), "camera:\n  width: 240\n  height: 180\n  fx: 200\n  fy: 200\n  cx: 120\n  cy: 90\n"
                               "imu:\n  time_offset: 0.1\nimu:\n  time_offset: 0.2\n");
  std::string m = configError([&] { (void)loadCalibration(d.file("c.yaml")); });
  EXPECT_NE(m.find("c.yaml:10"), std::string::npos) << m;
  EXPECT_NE(m.find("given twice (first at line 8)"), std::string::npos) << m;
  const std::string scene = readBytes(std::string(CELC_SOURCE_DIR) + "/config/scenes/davis240_rectangles.yaml");
  writeBytes(d.file("s.yaml"), scene + "duration: 2.0\n");
  m = configError([&] { (void)loadSynthConfig(d.file("s.yaml")); });
  EXPECT_NE(m.find("s.yaml:"), std::string::npos) << m;
  EXPECT_NE(m.find("'duration': given twice (first at line 7)"), std::string::npos) << m;
  writeBytes(d.file("b.yaml"), "sequences:\n  - label: a\n    path: x\n    path: y\n");
  m = configError([&] { (void)readBatch(d.file("b.yaml"), [](const std::string&) { return RunConfig{}; }); });
  EXPECT_NE(m.find("b.yaml:4"), std::string::npos) << m;
  EXPECT_NE(m.find("given twice (first at line 3)"), std::string::npos) << m;
}
