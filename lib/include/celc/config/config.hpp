#pragma once
/// \file config.hpp
/// The configuration of `celc simulate`: the scene, the solvers and the study,
/// one schema (core/fields.hpp) with units in config/simulate.yaml. Unknown
/// keys and wrong types are ConfigError naming the file, the line and the key.
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/sim/line_scene.hpp"
#include "celc/solver/solver.hpp"

namespace celc {

/// `celc simulate` configuration: the scene, the solvers and the study.
struct SimulateConfig {
  LineSceneOptions scene;
  /// The paper's preset (SolverOptions::paper()) with an empty model-error
  /// budget: the simulated calibration is exact, and each trial's own gyro
  /// error (scene.omega_noise) is added to gyro_bias_rad_s (runSweep).
  SolverOptions solver = [] {
    SolverOptions s = SolverOptions::paper();
    s.uncertainty.clearBudget();
    return s;
  }();
  std::vector<Method> methods = paperMethods();
  int trials = 500;
  std::uint64_t seed = 1;
  std::string validate() const;  ///< empty when valid
};

/// The schema: sections `scene`, `solver`, `study` (trials, seed, methods).
void describe(FieldVisitor& v, SimulateConfig& config);

/// Reads a YAML file onto the defaults; keys not given keep their defaults.
/// Throws ConfigError ("FILE:LINE: key 'a.b': ...").
SimulateConfig loadSimulateConfig(const std::string& path);
/// The same from a YAML string (`origin` names it in errors).
SimulateConfig parseSimulateConfig(const std::string& yaml, const std::string& origin);
/// Applies `key.path=value` (a YAML value) onto `config`, then validates.
void applySimulateSetting(const std::string& assignment, SimulateConfig& config);
/// The effective configuration as YAML (every key, with its unit and doc).
std::string toYaml(const SimulateConfig& config);

}  // namespace celc
