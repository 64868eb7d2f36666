#pragma once
/// \file config.hpp
/// YAML configuration mapped onto the options structs. One schema, units in
/// the comments of config/*.yaml. Unknown keys and wrong types are errors
/// that name the file, the key and its line (ConfigError).
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "celc/sim/line_scene.hpp"
#include "celc/solver/solver.hpp"

namespace celc {

struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// `celc simulate` configuration: the scene, the solvers and the study.
struct SimulateConfig {
  LineSceneOptions scene;
  SolverOptions solver;
  std::vector<Method> methods = allMethods();
  int trials = 500;
  std::uint64_t seed = 1;
};

/// Reads a YAML file (sections `scene`, `solver`, `study`); keys not given keep
/// their defaults. Throws ConfigError ("FILE:LINE: key 'a.b': ...").
SimulateConfig loadSimulateConfig(const std::string& path);
/// The same from a YAML string (`origin` names it in errors).
SimulateConfig parseSimulateConfig(const std::string& yaml, const std::string& origin);
/// The effective configuration as YAML (every key, with its value).
std::string toYaml(const SimulateConfig& config);

}  // namespace celc
