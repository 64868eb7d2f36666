#include "celc/config/config.hpp"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>

namespace celc {
namespace {

// A YAML map whose keys are read one by one; finish() rejects the rest.
class Section {
 public:
  Section(const YAML::Node& node, std::string origin, std::string path)
      : node_(node), origin_(std::move(origin)), path_(std::move(path)) {
    if (node_ && !node_.IsMap() && !node_.IsNull())
      throw ConfigError(where(node_) + "'" + path_ + "' must be a map of keys");
  }

  template <typename T>
  void get(const std::string& key, T& out) {
    known_.insert(key);
    if (!node_ || !node_.IsMap() || !node_[key]) return;
    const YAML::Node v = node_[key];
    try {
      out = v.as<T>();
    } catch (const YAML::Exception&) {
      throw ConfigError(where(v) + "key '" + full(key) + "': expected " + typeName<T>() +
                        ", got '" + scalarText(v) + "'");
    }
  }

  void getVec3(const std::string& key, Vec3& out) {
    std::vector<double> v{out.x(), out.y(), out.z()};
    get(key, v);
    if (v.size() != 3) throw ConfigError(where(node_[key]) + "key '" + full(key) + "': expected 3 numbers");
    out = Vec3(v[0], v[1], v[2]);
  }

  void getVec2(const std::string& key, Vec2& out) {
    std::vector<double> v{out.x(), out.y()};
    get(key, v);
    if (v.size() != 2) throw ConfigError(where(node_[key]) + "key '" + full(key) + "': expected 2 numbers [min, max]");
    out = Vec2(v[0], v[1]);
  }

  Section sub(const std::string& key) {
    known_.insert(key);
    return Section(node_ && node_.IsMap() ? node_[key] : YAML::Node(), origin_, full(key));
  }

  void finish() const {
    if (!node_ || !node_.IsMap()) return;
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!known_.count(k)) throw ConfigError(where(kv.first) + "unknown key '" + full(k) + "'");
    }
  }

  std::string where(const YAML::Node& n) const {
    const auto mark = n.Mark();
    return origin_ + (mark.line >= 0 ? ":" + std::to_string(mark.line + 1) : std::string()) + ": ";
  }

 private:
  std::string full(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  static std::string scalarText(const YAML::Node& n) {
    if (n.IsScalar()) return n.Scalar();
    return n.IsSequence() ? "a list" : (n.IsMap() ? "a map" : "null");
  }
  template <typename T>
  static std::string typeName() {
    if constexpr (std::is_same_v<T, bool>) return "true or false";
    else if constexpr (std::is_integral_v<T>) return "an integer";
    else if constexpr (std::is_floating_point_v<T>) return "a number";
    else if constexpr (std::is_same_v<T, std::string>) return "a string";
    else return "a list of numbers";
  }

  YAML::Node node_;
  std::string origin_, path_;
  std::set<std::string> known_;
};

template <typename Check>
void checkValid(const std::string& origin, const std::string& section, const Check& errors) {
  if (!errors.empty()) throw ConfigError(origin + ": section '" + section + "': " + errors);
}

void readSolver(Section s, SolverOptions& o) {
  Section l = s.sub("linear");
  l.get("max_rows", o.linear.max_rows);
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
  r.get("seed", o.refine.seed);
  r.get("function_tolerance", o.refine.function_tolerance);
  r.get("num_threads", o.refine.num_threads);
  r.finish();
  s.finish();
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
  readSolver(top.sub("solver"), cfg.solver);
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
  const auto& l = c.solver.linear;
  const auto& r = c.solver.refine;
  y << "# celc " << CELC_VERSION << " effective configuration (units: s, px, m, rad)\n"
    << "scene:\n"
    << "  n_lines: " << s.n_lines << "\n  events_per_line: " << s.events_per_line
    << "\n  duration: " << s.duration << "  # [s]\n  velocity: " << yamlList(s.velocity)
    << "  # [m/s]\n  omega: " << yamlList(s.omega) << "  # [rad/s]\n  event_noise_px: "
    << s.event_noise_px << "\n  line_noise_px: " << s.line_noise_px
    << "\n  omega_noise: " << s.omega_noise << "  # [rad/s]\n  outlier_fraction: "
    << s.outlier_fraction << "\n  x_range: [" << s.x_range.x() << ", " << s.x_range.y()
    << "]\n  y_range: [" << s.y_range.x() << ", " << s.y_range.y() << "]\n  z_range: ["
    << s.z_range.x() << ", " << s.z_range.y() << "]\n  motion_model: " << toString(s.motion)
    << "\n  omega_wobble: " << yamlList(s.omega_wobble) << "\n  gyro_rate_hz: " << s.gyro_rate_hz
    << "\n  camera: {width: " << s.camera.width << ", height: " << s.camera.height
    << ", fx: " << s.camera.fx << ", fy: " << s.camera.fy << ", cx: " << s.camera.cx
    << ", cy: " << s.camera.cy << "}\n"
    << "solver:\n  linear:\n    max_rows: " << l.max_rows << "\n    seed: " << l.seed
    << "\n    max_iterations: " << l.max_iterations << "\n    huber_k: " << l.huber_k
    << "\n    tolerance: " << l.tolerance << "\n    grid_directions: " << l.grid_directions
    << "\n    grid_starts: " << l.grid_starts << "\n    grid_rows: " << l.grid_rows
    << "\n    min_clusters: " << l.min_clusters << "\n    min_cluster_events: "
    << l.min_cluster_events << "\n    max_sigma_ratio: " << l.max_sigma_ratio
    << "\n    min_parallax_ratio: " << l.min_parallax_ratio << "\n    min_parallax_px: "
    << l.min_parallax_px << "\n    resolve_sign: " << (l.resolve_sign ? "true" : "false")
    << "\n  refine:\n    huber_px: " << r.huber_px << "\n    max_iterations: "
    << r.max_iterations << "\n    max_events: " << r.max_events << "\n    seed: " << r.seed
    << "\n    function_tolerance: " << r.function_tolerance << "\n    num_threads: "
    << r.num_threads << "\nstudy:\n  trials: " << c.trials << "\n  seed: " << c.seed
    << "\n  methods: [";
  for (size_t i = 0; i < c.methods.size(); ++i) y << (i ? ", " : "") << toString(c.methods[i]);
  y << "]\n";
  return y.str();
}

}  // namespace celc
