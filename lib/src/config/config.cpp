#include "celc/config/config.hpp"

#include "celc/core/yaml.hpp"

namespace celc {

namespace {
/// The `study` section's keys.
void describeStudy(FieldVisitor& s, SimulateConfig& c) {
  s.field({"trials", "", "random trials per level", atLeast(1)}, c.trials);
  s.field({"seed", "", "seed of the trials"}, c.seed);
  s.enumerations({"methods", "", "methods compared"}, c.methods, allMethods());
}
}  // namespace

std::string SimulateConfig::validate() const {
  SimulateConfig copy = *this;
  std::string e = inSection("scene", scene.validate()) + inSection("solver", solver.validate()) +
                  inSection("study", rangeProblems([&](FieldVisitor& v) { describeStudy(v, copy); }));
  if (methods.empty()) e += "study.methods: at least one; ";
  return e;
}

void describe(FieldVisitor& v, SimulateConfig& c) {
  v.section({"scene", "", "the paper's synthetic line scene (Sec. 5.1)"},
            [&](FieldVisitor& s) { describe(s, c.scene); });
  v.section({"solver", "", "the solvers"}, [&](FieldVisitor& s) { describe(s, c.solver); });
  v.section({"study", "", "the Monte-Carlo study"}, [&](FieldVisitor& s) { describeStudy(s, c); });
}

namespace {
void validated(const SimulateConfig& c, const std::string& origin) {
  if (const std::string err = c.validate(); !err.empty()) throw ConfigError(origin + ": " + err);
}
}  // namespace

SimulateConfig parseSimulateConfig(const std::string& yaml, const std::string& origin) {
  SimulateConfig c;
  readYaml(yaml, origin, [&](FieldVisitor& v) { describe(v, c); });
  validated(c, origin);
  return c;
}

SimulateConfig loadSimulateConfig(const std::string& path) {
  SimulateConfig c;
  readYamlFile(path, [&](FieldVisitor& v) { describe(v, c); });
  validated(c, path);
  return c;
}

void applySimulateSetting(const std::string& assignment, SimulateConfig& c) {
  SimulateConfig next = c;  // a failed assignment leaves `c` as it was
  applyAssignment(assignment, [&](FieldVisitor& v) { describe(v, next); });
  validated(next, "--set " + assignment);
  c = next;
}

std::string toYaml(const SimulateConfig& c) {
  SimulateConfig copy = c;
  return writeYaml([&](FieldVisitor& v) { describe(v, copy); },
                   {true, std::string("celc ") + CELC_VERSION +
                              " configuration of `celc simulate` (units in brackets)"});
}

}  // namespace celc
