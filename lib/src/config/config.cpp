#include "celc/config/config.hpp"

#include <yaml-cpp/yaml.h>

#include "yaml_section.hpp"

#include <fstream>
#include <set>
#include <sstream>

namespace celc {
namespace detail {

void readSolverSection(Section s, SolverOptions& o) {
  Section l = s.sub("linear");
  l.get("max_rows", o.linear.max_rows);
  l.get("balance_clusters", o.linear.balance_clusters);
  l.get("seed", o.linear.seed);
  l.get("max_iterations", o.linear.max_iterations);
  l.get("huber_k", o.linear.huber_k);
  l.get("tolerance", o.linear.tolerance);
  l.get("grid_directions", o.linear.grid_directions);
  l.get("grid_starts", o.linear.grid_starts);
  l.get("grid_rows", o.linear.grid_rows);
  l.get("min_clusters", o.linear.min_clusters);
  l.get("min_cluster_events", o.linear.min_cluster_events);
  l.get("max_sigma_ratio", o.linear.max_sigma_ratio);
  l.get("min_parallax_ratio", o.linear.min_parallax_ratio);
  l.get("min_parallax_px", o.linear.min_parallax_px);
  l.get("resolve_sign", o.linear.resolve_sign);
  l.finish();
  Section r = s.sub("refine");
  r.get("huber_px", o.refine.huber_px);
  r.get("max_iterations", o.refine.max_iterations);
  r.get("max_events", o.refine.max_events);
  r.get("balance_clusters", o.refine.balance_clusters);
  r.get("seed", o.refine.seed);
  r.get("function_tolerance", o.refine.function_tolerance);
  r.get("num_threads", o.refine.num_threads);
  r.finish();
  Section m = s.sub("ml");
  m.get("second_start", o.ml.second_start);
  m.get("second_start_max_twist", o.ml.second_start_max_twist);
  m.get("second_start_deg", o.ml.second_start_deg);
  m.get("grid_starts", o.ml.grid_starts);
  m.get("screen_events", o.ml.screen_events);
  m.finish();
  s.finish();
}

std::string solverYaml(const SolverOptions& o, const std::string& in) {
  std::ostringstream y;
  y.precision(17);
  const auto& l = o.linear;
  const auto& r = o.refine;
  y << in << "solver:\n"
    << in << "  linear:\n"
    << in << "    max_rows: " << l.max_rows << "\n"
    << in << "    balance_clusters: " << (l.balance_clusters ? "true" : "false") << "\n"
    << in << "    seed: " << l.seed << "\n"
    << in << "    max_iterations: " << l.max_iterations << "\n"
    << in << "    huber_k: " << l.huber_k << "\n"
    << in << "    tolerance: " << l.tolerance << "\n"
    << in << "    grid_directions: " << l.grid_directions << "\n"
    << in << "    grid_starts: " << l.grid_starts << "\n"
    << in << "    grid_rows: " << l.grid_rows << "\n"
    << in << "    min_clusters: " << l.min_clusters << "\n"
    << in << "    min_cluster_events: " << l.min_cluster_events << "\n"
    << in << "    max_sigma_ratio: " << l.max_sigma_ratio << "\n"
    << in << "    min_parallax_ratio: " << l.min_parallax_ratio << "\n"
    << in << "    min_parallax_px: " << l.min_parallax_px << "\n"
    << in << "    resolve_sign: " << (l.resolve_sign ? "true" : "false") << "\n"
    << in << "  refine:\n"
    << in << "    huber_px: " << r.huber_px << "\n"
    << in << "    max_iterations: " << r.max_iterations << "\n"
    << in << "    max_events: " << r.max_events << "\n"
    << in << "    balance_clusters: " << (r.balance_clusters ? "true" : "false") << "\n"
    << in << "    seed: " << r.seed << "\n"
    << in << "    function_tolerance: " << r.function_tolerance << "\n"
    << in << "    num_threads: " << r.num_threads << "\n"
    << in << "  ml:\n"
    << in << "    second_start: " << (o.ml.second_start ? "true" : "false") << "\n"
    << in << "    second_start_max_twist: " << o.ml.second_start_max_twist << "\n"
    << in << "    second_start_deg: " << o.ml.second_start_deg << "\n"
    << in << "    grid_starts: " << o.ml.grid_starts << "\n"
    << in << "    screen_events: " << o.ml.screen_events << "\n";
  return y.str();
}

}  // namespace detail

namespace {
using detail::Section;


template <typename Check>
void checkValid(const std::string& origin, const std::string& section, const Check& errors) {
  if (!errors.empty()) throw ConfigError(origin + ": section '" + section + "': " + errors);
}

void readScene(Section s, LineSceneOptions& o) {
  s.get("n_lines", o.n_lines);
  s.get("events_per_line", o.events_per_line);
  s.get("duration", o.duration);
  s.getVec3("velocity", o.velocity);
  s.getVec3("omega", o.omega);
  s.get("event_noise_px", o.event_noise_px);
  s.get("line_noise_px", o.line_noise_px);
  s.get("omega_noise", o.omega_noise);
  s.get("outlier_fraction", o.outlier_fraction);
  s.get("edge_offset_px", o.edge_offset_px);
  s.getVec2("x_range", o.x_range);
  s.getVec2("y_range", o.y_range);
  s.getVec2("z_range", o.z_range);
  std::string model = toString(o.motion);
  s.get("motion_model", model);
  try {
    o.motion = parseMotionModelKind(model);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(s.where(YAML::Node()) + "key 'scene.motion_model': " + e.what());
  }
  s.getVec3("omega_wobble", o.omega_wobble);
  s.get("gyro_rate_hz", o.gyro_rate_hz);
  Section c = s.sub("camera");
  c.get("width", o.camera.width);
  c.get("height", o.camera.height);
  c.get("fx", o.camera.fx);
  c.get("fy", o.camera.fy);
  c.get("cx", o.camera.cx);
  c.get("cy", o.camera.cy);
  c.finish();
  s.finish();
}

std::string yamlList(const Vec3& v) {
  std::ostringstream os;
  os.precision(17);
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

}  // namespace

SimulateConfig parseSimulateConfig(const std::string& yaml, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(origin + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax: " + e.msg);
  }
  SimulateConfig cfg;
  Section top(root, origin, "");
  readScene(top.sub("scene"), cfg.scene);
  detail::readSolverSection(top.sub("solver"), cfg.solver);
  Section study = top.sub("study");
  study.get("trials", cfg.trials);
  study.get("seed", cfg.seed);
  std::vector<std::string> methods;
  study.get("methods", methods);
  if (!methods.empty()) {
    cfg.methods.clear();
    for (const auto& m : methods) {
      try {
        cfg.methods.push_back(parseMethod(m));
      } catch (const std::invalid_argument& e) {
        throw ConfigError(origin + ": key 'study.methods': " + e.what());
      }
    }
  }
  study.finish();
  top.finish();
  checkValid(origin, "scene", cfg.scene.validate());
  checkValid(origin, "solver", cfg.solver.validate());
  if (cfg.trials < 1) throw ConfigError(origin + ": key 'study.trials': must be >= 1");
  return cfg;
}

SimulateConfig loadSimulateConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open configuration file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseSimulateConfig(ss.str(), path);
}

std::string toYaml(const SimulateConfig& c) {
  std::ostringstream y;
  y.precision(17);
  const auto& s = c.scene;
  y << "# celc " << CELC_VERSION << " effective configuration (units: s, px, m, rad)\n"
    << "scene:\n"
    << "  n_lines: " << s.n_lines << "\n  events_per_line: " << s.events_per_line
    << "\n  duration: " << s.duration << "  # [s]\n  velocity: " << yamlList(s.velocity)
    << "  # [m/s]\n  omega: " << yamlList(s.omega) << "  # [rad/s]\n  event_noise_px: "
    << s.event_noise_px << "\n  line_noise_px: " << s.line_noise_px
    << "\n  omega_noise: " << s.omega_noise << "  # [rad/s]\n  outlier_fraction: "
    << s.outlier_fraction << "\n  edge_offset_px: " << s.edge_offset_px << "  # [px]\n  x_range: [" << s.x_range.x() << ", " << s.x_range.y()
    << "]\n  y_range: [" << s.y_range.x() << ", " << s.y_range.y() << "]\n  z_range: ["
    << s.z_range.x() << ", " << s.z_range.y() << "]\n  motion_model: " << toString(s.motion)
    << "\n  omega_wobble: " << yamlList(s.omega_wobble) << "\n  gyro_rate_hz: " << s.gyro_rate_hz
    << "\n  camera: {width: " << s.camera.width << ", height: " << s.camera.height
    << ", fx: " << s.camera.fx << ", fy: " << s.camera.fy << ", cx: " << s.camera.cx
    << ", cy: " << s.camera.cy << "}\n"
    << detail::solverYaml(c.solver, "") << "study:\n  trials: " << c.trials << "\n  seed: " << c.seed
    << "\n  methods: [";
  for (size_t i = 0; i < c.methods.size(); ++i) y << (i ? ", " : "") << toString(c.methods[i]);
  y << "]\n";
  return y.str();
}

}  // namespace celc
