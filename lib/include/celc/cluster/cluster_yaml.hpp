#pragma once
/// \file cluster_yaml.hpp
/// The `cluster:` and `lines:` sections of a celc YAML config mapped onto the
/// options structs (keys = the struct field names, units in config/cluster.yaml).
#include <string>

#include "celc/cluster/cluster.hpp"
#include "celc/lines/line_fit.hpp"

namespace celc {

/// Overrides `cluster` (and `lines`, when given) with the keys present under the
/// top-level `cluster:` / `lines:` maps of `yaml_text`; absent keys keep their
/// values. Throws std::runtime_error "SOURCE:LINE: ..." on YAML syntax errors,
/// unknown keys, values of the wrong type, or options that fail validate().
void applyClusterYaml(const std::string& yaml_text, const std::string& source,
                      ClusterOptions& cluster, LineFitOptions* lines = nullptr);

}  // namespace celc
