#include "celc/cluster/cluster_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <map>
#include <stdexcept>

namespace celc {
namespace {

std::string where(const std::string& source, const YAML::Node& n) {
  return source + ":" + std::to_string(n.Mark().line + 1);
}

template <class T>
std::function<void(const YAML::Node&)> setter(T& field, const std::string& source,
                                              const std::string& key) {
  return [&field, source, key](const YAML::Node& n) {
    try {
      if (!n.IsScalar()) throw YAML::Exception(n.Mark(), "not a scalar");
      field = n.as<T>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(where(source, n) + ": '" + key + "' has the wrong type");
    }
  };
}

void applyMap(const YAML::Node& map, const std::string& source, const std::string& section,
              const std::map<std::string, std::function<void(const YAML::Node&)>>& keys) {
  if (!map) return;
  if (!map.IsMap()) throw std::runtime_error(where(source, map) + ": '" + section + "' must be a map");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    const auto it = keys.find(key);
    if (it == keys.end())
      throw std::runtime_error(where(source, kv.first) + ": unknown key '" + section + "." + key + "'");
    it->second(kv.second);
  }
}

}  // namespace

void applyClusterYaml(const std::string& yaml_text, const std::string& source,
                      ClusterOptions& c, LineFitOptions* lines) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(source + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root || root.IsNull()) return;
  if (!root.IsMap()) throw std::runtime_error(source + ": expected a map at the top level");
  ClusterOptions next = c;
  std::string method = toString(next.method);
  const std::map<std::string, std::function<void(const YAML::Node&)>> keys = {
      {"method", setter(method, source, "method")},
      {"c_px_per_s", setter(next.c_px_per_s, source, "c_px_per_s")},
      {"c_min_px_per_s", setter(next.c_min_px_per_s, source, "c_min_px_per_s")},
      {"c_max_px_per_s", setter(next.c_max_px_per_s, source, "c_max_px_per_s")},
      {"separate_polarity", setter(next.separate_polarity, source, "separate_polarity")},
      {"neighbours", setter(next.neighbours, source, "neighbours")},
      {"pcl_normal_radius_px", setter(next.pcl_normal_radius_px, source, "pcl_normal_radius_px")},
      {"grid_radius_px", setter(next.grid_radius_px, source, "grid_radius_px")},
      {"grow_radius_px", setter(next.grow_radius_px, source, "grow_radius_px")},
      {"time_radius_px", setter(next.time_radius_px, source, "time_radius_px")},
      {"grow_time_radius_px", setter(next.grow_time_radius_px, source, "grow_time_radius_px")},
      {"min_neighbours", setter(next.min_neighbours, source, "min_neighbours")},
      {"normal_reuse_px", setter(next.normal_reuse_px, source, "normal_reuse_px")},
      {"smoothness_deg", setter(next.smoothness_deg, source, "smoothness_deg")},
      {"curvature_threshold", setter(next.curvature_threshold, source, "curvature_threshold")},
      {"min_cluster_size", setter(next.min_cluster_size, source, "min_cluster_size")},
      {"max_cluster_size", setter(next.max_cluster_size, source, "max_cluster_size")},
      {"max_plane_rms_px", setter(next.max_plane_rms_px, source, "max_plane_rms_px")},
      {"ransac_threshold_px", setter(next.ransac_threshold_px, source, "ransac_threshold_px")},
      {"max_split", setter(next.max_split, source, "max_split")},
      {"min_time_span_s", setter(next.min_time_span_s, source, "min_time_span_s")},
      {"min_extent_px", setter(next.min_extent_px, source, "min_extent_px")},
      {"min_density_per_px2", setter(next.min_density_per_px2, source, "min_density_per_px2")},
      {"threads", setter(next.threads, source, "threads")},
      {"seed", setter(next.seed, source, "seed")},
  };
  applyMap(root["cluster"], source, "cluster", keys);
  try {
    next.method = parseClusterMethod(method);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where(source, root["cluster"]["method"]) + ": " + e.what());
  }
  if (const std::string err = next.validate(); !err.empty())
    throw std::runtime_error(source + ": cluster: " + err);
  if (lines != nullptr) {
    LineFitOptions l = *lines;
    applyMap(root["lines"], source, "lines",
             {{"interval_s", setter(l.interval_s, source, "interval_s")},
              {"interval_fraction", setter(l.interval_fraction, source, "interval_fraction")},
              {"min_events", setter(l.min_events, source, "min_events")},
              {"max_rms_px", setter(l.max_rms_px, source, "max_rms_px")},
              {"min_length_px", setter(l.min_length_px, source, "min_length_px")}});
    if (const std::string err = l.validate(); !err.empty())
      throw std::runtime_error(source + ": lines: " + err);
    *lines = l;
  }
  c = next;
}

}  // namespace celc
