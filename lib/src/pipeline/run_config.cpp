#include "celc/pipeline/run_config.hpp"

#include <algorithm>
#include <cmath>

#include "celc/core/yaml.hpp"

namespace celc {

std::string toString(OmegaSource source) { return source == OmegaSource::Gyro ? "gyro" : "fixed"; }

std::string toString(StillBias mode) {
  return mode == StillBias::Auto ? "auto" : mode == StillBias::On ? "true" : "false";
}

namespace {
/// The `motion:` section's keys (the gyro window's among them).
void describeMotion(FieldVisitor& s, RunConfig& c) {
  s.enumeration({"model", "", "gyro_integrated: the gyro's rotation within the window; constant_twist: its mean (paper)"}, c.motion,
                {MotionModelKind::ConstantTwist, MotionModelKind::GyroIntegrated});
  s.enumeration({"omega_source", "", "gyro: the recording's IMU; fixed: fixed_omega"}, c.omega_source,
                {OmegaSource::Gyro, OmegaSource::Fixed});
  s.field({"fixed_omega", "rad/s", "camera-frame angular velocity with omega_source fixed", anyFinite()},
          c.fixed_omega);
  s.field({"gyro_bias", "rad/s",
           "constant gyro bias, IMU frame, subtracted from every sample (celc info estimates it)", anyFinite()},
          c.gyro_bias);
  s.enumeration({"gyro_bias_from_still", "",
                 "the mean gyro rate over the recording's first still second as the bias: auto = when it is "
                 "significant and gyro_bias is zero; true = always (an error without one); false = never"},
                c.gyro_bias_from_still, {StillBias::Auto, StillBias::On, StillBias::Off});
  describe(s, c.gyro);
  describe(s, c.accelerometer);
}
}  // namespace

std::string RunConfig::windowsValidate() const {
  if (window_policy == WindowPolicy::Events && windows.events_per_window == 0)
    return "events: windows.policy events needs events > 0; ";
  if (window_policy == WindowPolicy::Seconds && !(windows.seconds_per_window > 0.0))
    return "seconds: windows.policy seconds needs seconds > 0; ";
  if (window_policy != WindowPolicy::Parallax) {
    if (window_policy == WindowPolicy::Events && windows.seconds_per_window != 0.0)
      return "seconds: set with windows.policy events (use one of them); ";
    if (window_policy == WindowPolicy::Seconds && windows.events_per_window != 0)
      return "events: set with windows.policy seconds (use one of them); ";
    return windows.validate();
  }
  // Parallax: events and seconds belong to the other policies and must not
  // be set by mistake; the window's own checks run on a window of max_seconds.
  if (!std::isfinite(windows.seconds_per_window) || windows.seconds_per_window < 0.0) return windows.validate();
  if (windows.events_per_window != 0 || windows.seconds_per_window != 0.0)
    return "policy: events / seconds are set but the policy is parallax (set windows.policy: events or seconds); ";
  WindowOptions w = windows;
  w.seconds_per_window = parallax.max_seconds > 0.0 && std::isfinite(parallax.max_seconds) ? parallax.max_seconds : 1.0;
  std::string e = w.validate();
  if (e.empty() && windows.overlap != 0.0) e += "overlap: the parallax policy's windows do not overlap (set 0); ";
  return e + parallax.validate();
}

std::string RunConfig::validate() const {
  RunConfig copy = *this;
  std::string e = inSection("input", reader.validate()) + inSection("windows", windowsValidate()) +
                  inSection("motion", rangeProblems([&](FieldVisitor& v) { describeMotion(v, copy); })) +
                  cluster.validate() + observations.validate() + inSection("solver", solver.validate()) +
                  inSection("groundtruth", groundtruth.validate());
  if (methods.empty()) e += "methods: at least one; ";
  for (size_t i = 0; i < methods.size(); ++i)
    if (std::find(methods.begin(), methods.begin() + static_cast<std::ptrdiff_t>(i), methods[i]) !=
        methods.begin() + static_cast<std::ptrdiff_t>(i)) {
      e += "methods: " + toString(methods[i]) + " listed twice; ";
      break;
    }
  if (gyro_bias_from_still == StillBias::On && !gyro_bias.isZero(0.0))
    e += "motion.gyro_bias_from_still: set with motion.gyro_bias (use one of them); ";
  if (gyro_bias_from_still == StillBias::On && omega_source != OmegaSource::Gyro)
    e += "motion.gyro_bias_from_still: needs motion.omega_source gyro; ";
  // One line: the problems joined by "; ", without the last separator.
  while (!e.empty() && (e.back() == ' ' || e.back() == ';')) e.pop_back();
  return e;
}

void describeClustering(FieldVisitor& v, ClusterOptions& cluster, LineFitOptions& lines) {
  v.section({"cluster", "", "space-time clustering (docs/clustering.md)"},
            [&](FieldVisitor& s) { describe(s, cluster); });
  v.section({"lines", "", "boundary lines l1, l3 (and l2) of each cluster"},
            [&](FieldVisitor& s) { describe(s, lines); });
}

void describe(FieldVisitor& v, RunConfig& c) {
  v.section({"input", "", "reading the recording"}, [&](FieldVisitor& s) { describe(s, c.reader); });
  v.section({"windows", "", "cutting the stream into windows (pipeline/window_policy.hpp)"}, [&](FieldVisitor& s) {
    s.enumeration({"policy", "",
                   "parallax: grow each window until its lines show parallax_px; events / seconds: fixed windows"},
                  c.window_policy, {WindowPolicy::Parallax, WindowPolicy::Events, WindowPolicy::Seconds});
    describe(s, c.windows);
    describe(s, c.parallax);
    s.field({"max_events_in_flight", "events",
             "events of the windows read and not yet processed: a window is read when those in flight leave "
             "room for one as large as the last read, and always when there are none (a window larger than the "
             "last can pass the bound by the difference); about 24 B per event, 100 B more while processed; "
             "0 = no bound"},
            c.max_events_in_flight);
  });
  v.section({"motion", "", "motion model and angular velocity"}, [&](FieldVisitor& s) { describeMotion(s, c); });
  describeClustering(v, c.cluster, c.observations.lines);
  v.section({"observations", "", "clusters turned into the solvers' observations"},
            [&](FieldVisitor& s) { describe(s, c.observations); });
  v.section({"solver", "", "the solvers"}, [&](FieldVisitor& s) { describe(s, c.solver); });
  v.enumerations({"methods", "", "methods run on every window"}, c.methods, allMethods());
  v.section({"groundtruth", "", "camera-frame velocity from the pose file"},
            [&](FieldVisitor& s) { describe(s, c.groundtruth); });
  v.field({"seed", "", "seeds the solvers' row subsets (per window: seed + index)"}, c.seed);
}

namespace {
void validated(const RunConfig& c, const std::string& origin) {
  if (const std::string err = c.validate(); !err.empty()) throw ConfigError(origin + ": " + err);
}
}  // namespace

void applyRunConfig(const std::string& yaml, const std::string& origin, RunConfig& c) {
  RunConfig next = c;  // a failed apply leaves `c` as it was
  readYaml(yaml, origin, [&](FieldVisitor& v) { describe(v, next); });
  validated(next, origin);
  c = next;
}

RunConfig loadRunConfig(const std::string& path) {
  RunConfig c;
  readYamlFile(path, [&](FieldVisitor& v) { describe(v, c); });
  validated(c, path);
  return c;
}

void applyRunSettings(const std::vector<std::string>& assignments, RunConfig& c) {
  if (assignments.empty()) return;
  RunConfig next = c;
  std::string origin;
  for (const std::string& a : assignments) {
    applyAssignment(a, [&](FieldVisitor& v) { describe(v, next); });
    origin += (origin.empty() ? "--set " : " --set ") + a;
  }
  validated(next, origin);
  c = next;
}

void applyRunSetting(const std::string& assignment, RunConfig& c) {
  RunConfig next = c;
  applyAssignment(assignment, [&](FieldVisitor& v) { describe(v, next); });
  validated(next, "--set " + assignment);
  c = next;
}

std::string toYaml(const RunConfig& c) {
  RunConfig copy = c;
  return writeYaml([&](FieldVisitor& v) { describe(v, copy); },
                   {true, std::string("celc ") + CELC_VERSION +
                              " configuration of `celc run` / `celc batch` (units in brackets)"});
}

const std::vector<std::string>& resultNeutralKeys() {
  static const std::vector<std::string> keys = {"cluster.threads", "windows.read_batch", "windows.max_events_in_flight"};
  return keys;
}

std::string firstConfigDifference(const RunConfig& a, const RunConfig& b) {
  RunConfig ca = a, cb = b;
  const auto fa = listFields([&](FieldVisitor& v) { describe(v, ca); });
  const auto fb = listFields([&](FieldVisitor& v) { describe(v, cb); });
  const auto& neutral = resultNeutralKeys();
  for (std::size_t i = 0; i < std::max(fa.size(), fb.size()); ++i) {
    if (i >= fa.size() || i >= fb.size() || fa[i].key != fb[i].key)  // list lengths differ
      return (i < fa.size() ? fa[i].key : fb[i].key) + ": present in one configuration only";
    if (std::find(neutral.begin(), neutral.end(), fa[i].key) != neutral.end()) continue;
    if (fa[i].value != fb[i].value) return fa[i].key + ": " + fa[i].value + " vs " + fb[i].value;
  }
  return {};
}

}  // namespace celc
