// The YAML configuration: defaults, round trip, and errors that name the key and line.
#include <gtest/gtest.h>

#include <fstream>

#include "celc/config/config.hpp"

using namespace celc;

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
