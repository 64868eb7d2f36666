// Helpers shared by the binding files (common.hpp).
#include "common.hpp"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "celc/core/yaml.hpp"
#include "celc/io/event_reader.hpp"

namespace celc::py {

static_assert(sizeof(Event) == 24 && offsetof(Event, t) == 0 && offsetof(Event, x) == 8 &&
                  offsetof(Event, y) == 12 && offsetof(Event, on) == 16,
              "eventDtype() describes celc::Event byte for byte");
static_assert(sizeof(bool) == 1, "numpy's bool is one byte");
static_assert(sizeof(Vec3) == 3 * sizeof(double), "a Vec3 is three packed doubles");

namespace {

pyb::dtype structDtype(const std::vector<std::string>& names, const std::vector<pyb::object>& formats,
                       const std::vector<std::size_t>& offsets, std::size_t itemsize) {
  pyb::dict spec;
  spec["names"] = names;
  spec["formats"] = formats;
  spec["offsets"] = offsets;
  spec["itemsize"] = itemsize;
  return pyb::dtype::from_args(spec);
}

}  // namespace

pyb::dtype eventDtype() {
  static const pyb::dtype* dt = new pyb::dtype(structDtype(
      {"t", "x", "y", "p"}, {pyb::str("<f8"), pyb::str("<f4"), pyb::str("<f4"), pyb::str("?")},
      {offsetof(Event, t), offsetof(Event, x), offsetof(Event, y), offsetof(Event, on)}, sizeof(Event)));
  return *dt;
}

pyb::dtype imuDtype() {
  const std::size_t gyro = offsetof(ImuSample, gyro), acc = offsetof(ImuSample, accel);
  static const pyb::dtype* dt = new pyb::dtype(structDtype(
      {"t", "gyro", "acc"},
      {pyb::str("<f8"), pyb::make_tuple("<f8", pyb::make_tuple(3)), pyb::make_tuple("<f8", pyb::make_tuple(3))},
      {offsetof(ImuSample, t), gyro, acc}, sizeof(ImuSample)));
  return *dt;
}

std::vector<Event> eventsFromPython(const pyb::handle& events) {
  if (pyb::isinstance<pyb::array>(events)) {
    auto arr = pyb::reinterpret_borrow<pyb::array>(events);
    if (arr.dtype().equal(eventDtype())) {
      if (arr.ndim() != 1) throw pyb::value_error("events: expected a 1-D array");
      // Our own layout: copy the records as they are (contiguous or strided).
      std::vector<Event> out(static_cast<std::size_t>(arr.shape(0)));
      const auto* base = static_cast<const char*>(arr.data());
      const pyb::ssize_t stride = arr.strides(0);
      for (std::size_t i = 0; i < out.size(); ++i)
        std::memcpy(&out[i], base + static_cast<pyb::ssize_t>(i) * stride, sizeof(Event));
      return out;
    }
  }
  // Any other layout: the fields one by one, converted once.
  auto field = [&](const char* name) {
    try {
      return pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(events[name]);
    } catch (const pyb::error_already_set&) {
      throw pyb::value_error(std::string("events: no field '") + name + "' (expected t, x, y and optionally p)");
    }
  };
  const auto t = field("t"), x = field("x"), y = field("y");
  if (!t || !x || !y || t.ndim() != 1 || x.ndim() != 1 || y.ndim() != 1 || x.shape(0) != t.shape(0) ||
      y.shape(0) != t.shape(0))
    throw pyb::value_error("events: t, x, y must be 1-D arrays of one length");
  pyb::array_t<bool, pyb::array::c_style | pyb::array::forcecast> p;
  bool has_p = false;
  try {
    p = pyb::array_t<bool, pyb::array::c_style | pyb::array::forcecast>::ensure(events["p"]);
    has_p = p && p.ndim() == 1 && p.shape(0) == t.shape(0);
  } catch (const pyb::error_already_set&) {
    has_p = false;
  }
  std::vector<Event> out(static_cast<std::size_t>(t.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto k = static_cast<pyb::ssize_t>(i);
    out[i] = Event{t.at(k), static_cast<float>(x.at(k)), static_cast<float>(y.at(k)), has_p ? p.at(k) : true};
  }
  return out;
}

std::string yamlValue(const pyb::handle& value) {
  if (pyb::isinstance<pyb::str>(value)) {
    std::string quoted = "'";
    for (char c : value.cast<std::string>()) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    return quoted + "'";
  }
  // Python numbers and numpy scalars by their kind.
  char kind = 0;
  if (pyb::isinstance<pyb::bool_>(value)) kind = 'b';
  else if (pyb::isinstance<pyb::int_>(value)) kind = 'i';
  else if (pyb::isinstance<pyb::float_>(value)) kind = 'f';
  else if (pyb::isinstance(value, pyb::module_::import("numpy").attr("generic")))
    kind = value.attr("dtype").attr("kind").cast<std::string>()[0];
  if (kind == 'b') return pyb::bool_(pyb::reinterpret_borrow<pyb::object>(value)) ? "true" : "false";
  if (kind == 'i' || kind == 'u') return pyb::str(pyb::int_(pyb::reinterpret_borrow<pyb::object>(value)));
  if (kind == 'f') {
    const double d = pyb::float_(pyb::reinterpret_borrow<pyb::object>(value)).cast<double>();
    if (std::isnan(d)) return ".nan";
    if (std::isinf(d)) return d > 0 ? ".inf" : "-.inf";
    return pyb::repr(pyb::float_(d)).cast<std::string>();  // the shortest text that reads back exactly
  }
  if (pyb::isinstance<pyb::dict>(value)) {
    std::string out = "{";
    for (auto item : pyb::reinterpret_borrow<pyb::dict>(value)) {
      out += (out.size() > 1 ? ", " : "") + pyb::str(item.first).cast<std::string>() + ": " + yamlValue(item.second);
    }
    return out + "}";
  }
  if (pyb::isinstance<pyb::array>(value) || pyb::isinstance<pyb::sequence>(value)) {
    pyb::object list = pyb::isinstance<pyb::array>(value) ? value.attr("tolist")() : pyb::reinterpret_borrow<pyb::object>(value);
    std::string out = "[";
    for (auto item : list) out += (out.size() > 1 ? ", " : "") + yamlValue(item);
    return out + "]";
  }
  throw pyb::value_error("cannot give a " + pyb::str(value.get_type().attr("__name__")).cast<std::string>() +
                         " as an option value (bool, number, str, list or dict)");
}

namespace {

void flatten(const pyb::handle& options, const std::string& prefix, std::vector<std::string>& out) {
  for (auto item : pyb::reinterpret_borrow<pyb::dict>(options)) {
    const std::string key = prefix + pyb::str(item.first).cast<std::string>();
    if (pyb::isinstance<pyb::dict>(item.second)) flatten(item.second, key + ".", out);
    else out.push_back(key + "=" + yamlValue(item.second));
  }
}

}  // namespace

std::vector<std::string> assignments(const pyb::handle& options) {
  std::vector<std::string> out;
  if (options.is_none()) return out;
  if (pyb::isinstance<pyb::dict>(options)) {
    flatten(options, "", out);
  } else if (pyb::isinstance<pyb::str>(options)) {
    out.push_back(options.cast<std::string>());
  } else {
    for (auto item : options) {
      if (!pyb::isinstance<pyb::str>(item)) throw pyb::value_error("options: expected a dict or 'key=value' strings");
      out.push_back(item.cast<std::string>());
    }
  }
  return out;
}

namespace {

// A YAML map built from dotted keys: one document for readYaml.
struct YamlNode {
  std::string value;  // a leaf's YAML flow value
  std::vector<std::pair<std::string, YamlNode>> children;
  void write(std::string& out, const std::string& indent) const {
    for (const auto& [key, node] : children) {
      if (node.children.empty()) out += indent + key + ": " + node.value + "\n";
      else {
        out += indent + key + ":\n";
        node.write(out, indent + "  ");
      }
    }
  }
};

}  // namespace

void applyDict(const pyb::handle& options, const std::string& origin, const Describe& describe) {
  const std::vector<std::string> items = assignments(options);
  if (items.empty()) return;
  // One document for all of them (one parse: a dict of options costs
  // microseconds, not one YAML read per key).
  YamlNode root;
  for (const std::string& a : items) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0) throw ConfigError(origin + ": '" + a + "': expected key.path=value");
    YamlNode* node = &root;
    std::stringstream path(a.substr(0, eq));
    for (std::string part; std::getline(path, part, '.');) {
      if (part.empty() || part.find_first_of(" :#[]{}'\"") != std::string::npos)
        throw ConfigError(origin + ": '" + a.substr(0, eq) + "': expected names between the dots");
      auto it = std::find_if(node->children.begin(), node->children.end(),
                             [&](const auto& c) { return c.first == part; });
      if (it == node->children.end()) {
        node->children.emplace_back(part, YamlNode{});
        it = std::prev(node->children.end());
      }
      node = &it->second;
    }
    if (!node->children.empty() || !node->value.empty())
      throw ConfigError(origin + ": key '" + a.substr(0, eq) + "' given twice");
    node->value = a.substr(eq + 1);
  }
  std::string yaml;
  root.write(yaml, "");
  readGeneratedYaml(yaml, origin, describe);
}

std::string pathString(const pyb::handle& path) {
  // os.fsdecode: str, bytes and path-like objects alike (bytes decoded as the
  // file system does, not printed as "b'...'").
  const std::string p = pyb::module_::import("os").attr("fsdecode")(path).cast<std::string>();
  if (p.find('\0') != std::string::npos)
    throw pyb::value_error("path " + detail::printable(p, 4096) + ": contains a NUL byte");
  return p;
}

std::string existingPath(const pyb::handle& path) {
  std::string p = pathString(path);
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) {
    PyErr_SetString(PyExc_FileNotFoundError, (detail::printable(p, 4096) + ": no such file or directory").c_str());
    throw pyb::error_already_set();
  }
  return p;
}

}  // namespace celc::py
