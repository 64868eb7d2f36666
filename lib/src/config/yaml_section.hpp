#pragma once
// Internal: reading a YAML map key by key with errors that name the file, the
// line and the full key; finish() rejects keys nobody asked for.
#include <yaml-cpp/yaml.h>

#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "celc/config/config.hpp"

namespace celc::detail {

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

void readSolverSection(Section s, SolverOptions& o);
std::string solverYaml(const SolverOptions& o, const std::string& indent);

}  // namespace celc::detail
