#include "celc/pipeline/run_config.hpp"

#include <fstream>
#include <sstream>

#include "celc/cluster/cluster_yaml.hpp"
#include "celc/config/config.hpp"
#include "config/yaml_section.hpp"

namespace celc {

using detail::Section;

std::string RunConfig::validate() const {
  std::string e = reader.validate() + windows.validate() + gyro.validate() + cluster.validate() +
                  observations.validate() + solver.validate() + groundtruth.validate();
  if (methods.empty()) e += "methods: at least one; ";
  if (!fixed_omega.allFinite()) e += "motion.fixed_omega must be finite; ";
  return e;
}

void applyRunConfig(const std::string& yaml, const std::string& origin, RunConfig& c) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(origin + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax: " + e.msg);
  }
  Section top(root, origin, "");
  {
    Section s = top.sub("input");
    s.get("width", c.reader.width);
    s.get("height", c.reader.height);
    std::string columns = "auto";
    s.get("imu_columns", columns);
    try {
      c.reader.imu_columns = io::parseImuColumns(columns);
    } catch (const std::exception& e) {
      throw ConfigError(origin + ": key 'input.imu_columns': " + e.what());
    }
    s.get("time_scale", c.reader.text_time_scale);
    s.get("strict", c.reader.strict);
    s.finish();
  }
  {
    Section s = top.sub("windows");
    s.get("events", c.windows.events_per_window);
    s.get("seconds", c.windows.seconds_per_window);
    s.get("overlap", c.windows.overlap);
    s.get("t_start", c.windows.t_start);
    s.get("t_end", c.windows.t_end);
    s.get("keep_partial", c.windows.keep_partial);
    s.finish();
  }
  {
    Section s = top.sub("motion");
    std::string model = toString(c.motion), source = c.omega_source == OmegaSource::Gyro ? "gyro" : "fixed";
    s.get("model", model);
    s.get("omega_source", source);
    s.getVec3("fixed_omega", c.fixed_omega);
    s.get("gyro_max_gap", c.gyro.max_gap);
    s.finish();
    try {
      c.motion = parseMotionModelKind(model);
    } catch (const std::exception& e) {
      throw ConfigError(origin + ": key 'motion.model': " + e.what());
    }
    if (source != "gyro" && source != "fixed")
      throw ConfigError(origin + ": key 'motion.omega_source': expected gyro or fixed, got '" + source + "'");
    c.omega_source = source == "gyro" ? OmegaSource::Gyro : OmegaSource::Fixed;
  }
  // `cluster:` and `lines:` belong to the clustering module's schema.
  top.sub("cluster");
  top.sub("lines");
  applyClusterYaml(yaml, origin, c.cluster, &c.observations.lines);
  {
    Section s = top.sub("observations");
    s.get("min_events", c.observations.min_events);
    s.finish();
  }
  detail::readSolverSection(top.sub("solver"), c.solver);
  std::vector<std::string> methods;
  top.get("methods", methods);
  if (!methods.empty()) {
    c.methods.clear();
    for (const auto& m : methods) {
      try {
        c.methods.push_back(parseMethod(m));
      } catch (const std::exception& e) {
        throw ConfigError(origin + ": key 'methods': " + e.what());
      }
    }
  }
  {
    Section s = top.sub("groundtruth");
    s.get("half_width", c.groundtruth.half_width);
    s.get("degree", c.groundtruth.degree);
    s.get("min_poses", c.groundtruth.min_poses);
    s.get("samples", c.groundtruth.samples);
    s.finish();
  }
  top.get("seed", c.seed);
  top.finish();
  if (const std::string err = c.validate(); !err.empty()) throw ConfigError(origin + ": " + err);
}

RunConfig loadRunConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open configuration file");
  std::stringstream ss;
  ss << in.rdbuf();
  RunConfig c;
  applyRunConfig(ss.str(), path, c);
  return c;
}

namespace {
std::string number(double x) {
  if (std::isinf(x)) return x > 0 ? ".inf" : "-.inf";
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}
}  // namespace

std::string toYaml(const RunConfig& c) {
  std::ostringstream y;
  const auto& k = c.cluster;
  const auto& l = c.observations.lines;
  const char* columns = c.reader.imu_columns == io::ImuColumns::Auto
                            ? "auto"
                            : (c.reader.imu_columns == io::ImuColumns::GyroFirst ? "gyro_first" : "rpg");
  y << "# celc " << CELC_VERSION << " effective configuration (units: s, px, m, rad)\n"
    << "input:\n  width: " << c.reader.width << "\n  height: " << c.reader.height
    << "\n  imu_columns: " << columns << "\n  time_scale: " << number(c.reader.text_time_scale)
    << "\n  strict: " << (c.reader.strict ? "true" : "false") << "\n"
    << "windows:\n  events: " << c.windows.events_per_window << "\n  seconds: "
    << number(c.windows.seconds_per_window) << "\n  overlap: " << number(c.windows.overlap)
    << "\n  t_start: " << number(c.windows.t_start) << "\n  t_end: " << number(c.windows.t_end)
    << "\n  keep_partial: " << (c.windows.keep_partial ? "true" : "false") << "\n"
    << "motion:\n  model: " << toString(c.motion) << "\n  omega_source: "
    << (c.omega_source == OmegaSource::Gyro ? "gyro" : "fixed") << "\n  fixed_omega: ["
    << number(c.fixed_omega.x()) << ", " << number(c.fixed_omega.y()) << ", "
    << number(c.fixed_omega.z()) << "]\n  gyro_max_gap: " << number(c.gyro.max_gap) << "\n"
    << "cluster:\n  method: " << toString(k.method) << "\n  c_px_per_s: " << number(k.c_px_per_s)
    << "\n  c_min_px_per_s: " << number(k.c_min_px_per_s) << "\n  c_max_px_per_s: "
    << number(k.c_max_px_per_s) << "\n  separate_polarity: " << (k.separate_polarity ? "true" : "false")
    << "\n  neighbours: " << k.neighbours << "\n  pcl_normal_radius_px: " << number(k.pcl_normal_radius_px)
    << "\n  grid_radius_px: " << k.grid_radius_px << "\n  grow_radius_px: " << k.grow_radius_px
    << "\n  time_radius_px: " << number(k.time_radius_px) << "\n  grow_time_radius_px: "
    << number(k.grow_time_radius_px) << "\n  min_neighbours: " << k.min_neighbours
    << "\n  smoothness_deg: " << number(k.smoothness_deg) << "\n  curvature_threshold: "
    << number(k.curvature_threshold) << "\n  min_cluster_size: " << k.min_cluster_size
    << "\n  max_cluster_size: " << k.max_cluster_size << "\n  max_plane_rms_px: "
    << number(k.max_plane_rms_px) << "\n  ransac_threshold_px: " << number(k.ransac_threshold_px)
    << "\n  max_split: " << k.max_split << "\n  min_time_span_s: " << number(k.min_time_span_s)
    << "\n  min_extent_px: " << number(k.min_extent_px) << "\n  min_density_per_px2: "
    << number(k.min_density_per_px2) << "\n  threads: " << k.threads << "\n  seed: " << k.seed
    << "\nlines:\n  interval_s: " << number(l.interval_s) << "\n  interval_fraction: "
    << number(l.interval_fraction) << "\n  min_events: " << l.min_events << "\n  max_rms_px: "
    << number(l.max_rms_px) << "\n  min_length_px: " << number(l.min_length_px) << "\n"
    << "observations:\n  min_events: " << c.observations.min_events << "\n"
    << detail::solverYaml(c.solver, "") << "methods: [";
  for (size_t i = 0; i < c.methods.size(); ++i) y << (i ? ", " : "") << toString(c.methods[i]);
  y << "]\ngroundtruth:\n  half_width: " << number(c.groundtruth.half_width)
    << "\n  degree: " << c.groundtruth.degree << "\n  min_poses: " << c.groundtruth.min_poses
    << "\n  samples: " << c.groundtruth.samples << "\nseed: " << c.seed << "\n";
  return y.str();
}

}  // namespace celc
