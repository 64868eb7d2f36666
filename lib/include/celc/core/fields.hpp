#pragma once
/// \file fields.hpp
/// The one schema of every options struct. Each struct declares its fields
/// once, in a `describe(FieldVisitor&, Options&)` function beside it: key,
/// member, unit and a one-line doc; the default is the member's initial value.
/// YAML reading and writing, `--set`, the help text of the common options,
/// the comments of the shipped config/*.yaml files and the round-trip tests
/// are visitors over that one declaration (config/yaml_schema.hpp).
#include <cstdint>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

/// A configuration error: names the file (or the command-line option), the
/// line when known (0 = unknown) and the dotted key.
struct ConfigError : std::runtime_error {
  ConfigError(std::string origin, int line, std::string key, const std::string& what);
  /// Without a place: a message that already says where.
  explicit ConfigError(const std::string& message);
  std::string origin;  ///< file path or "--set key=value"
  int line = 0;        ///< 1-based, 0 when unknown
  std::string key;     ///< dotted key, e.g. "solver.linear.huber_k"
};

/// The valid values of a numeric field: from min to max, either end
/// excluded when open, infinite ends unbounded. A range that checks at all
/// (a finite end, or `finite`) also needs a finite value; the default range
/// holds every value.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  ///< min itself is not valid
  bool max_open = false;  ///< max itself is not valid
  bool finite = false;    ///< without finite ends: any finite value
  /// Whether the range constrains the value at all.
  bool checks() const { return finite || std::isfinite(min) || std::isfinite(max); }
  /// Whether `x` is valid: always when the range does not check; else finite and within.
  bool contains(double x) const;
  /// ">= 0", "> 0", "<= 1", "in [0, 1)", "finite"; "" when the range does not check.
  std::string text() const;
};
/// x and above.
inline Range atLeast(double x) { return {x, std::numeric_limits<double>::infinity(), false, false, false}; }
/// Above x, x excluded.
inline Range above(double x) { return {x, std::numeric_limits<double>::infinity(), true, false, false}; }
/// [lo, hi].
inline Range within(double lo, double hi) { return {lo, hi, false, false, false}; }
/// [lo, hi), hi excluded.
inline Range withinBelow(double lo, double hi) { return {lo, hi, false, true, false}; }
/// (lo, hi], lo excluded.
inline Range withinAbove(double lo, double hi) { return {lo, hi, true, false, false}; }
/// Any finite value.
inline Range anyFinite() {
  return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), false, false, true};
}

/// What a field is: its key (one YAML map key), unit ("" when none; "-" for
/// dimensionless ratios), a one-line doc and its valid range (numbers; a
/// list's every element). Choices are given where a field is visited
/// (FieldVisitor::choice).
struct FieldInfo {
  const char* key;
  const char* unit;
  const char* doc;
  Range range = {};
};

/// Visits the fields of an options struct. A reader writes the members, a
/// writer reads them; both go through the same describe() function, in its
/// order. Every member access is by reference.
class FieldVisitor {
 public:
  virtual ~FieldVisitor() = default;

  virtual void field(const FieldInfo& info, bool& value) = 0;
  virtual void field(const FieldInfo& info, int& value) = 0;
  virtual void field(const FieldInfo& info, unsigned& value) = 0;
  virtual void field(const FieldInfo& info, long& value) = 0;
  virtual void field(const FieldInfo& info, unsigned long& value) = 0;
  virtual void field(const FieldInfo& info, double& value) = 0;
  virtual void field(const FieldInfo& info, std::string& value) = 0;
  virtual void field(const FieldInfo& info, Vec2& value) = 0;
  virtual void field(const FieldInfo& info, Vec3& value) = 0;
  /// A list of numbers whose length is one of `sizes` (empty: any length).
  virtual void field(const FieldInfo& info, std::vector<double>& value,
                     const std::vector<std::size_t>& sizes) = 0;
  /// One name of a fixed set (an enum's spelling).
  virtual void choice(const FieldInfo& info, std::string& value,
                      const std::vector<std::string>& allowed) = 0;
  /// A list of names of a fixed set (e.g. methods).
  virtual void choices(const FieldInfo& info, std::vector<std::string>& value,
                       const std::vector<std::string>& allowed) = 0;
  /// A nested map whose fields `body` visits.
  virtual void section(const FieldInfo& info, const std::function<void(FieldVisitor&)>& body) = 0;
  /// A list of maps: `count` is the list's length (a reader sets it before
  /// the items are visited); `item(i, v)` visits the i-th map.
  virtual void sequence(const FieldInfo& info, std::size_t& count,
                        const std::function<void(std::size_t, FieldVisitor&)>& item) = 0;

  /// A reader fails when `key` (of the current map) is absent; others do nothing.
  virtual void require(const char* key) { (void)key; }
  /// The struct member a converted field stands for (an enum read through its
  /// name, a matrix through a list): lets a visitor see which bytes of a
  /// struct the schema covers. Does nothing by default.
  virtual void member(const void* address, std::size_t size) { (void)address, (void)size; }
  /// A reader: whether the current map holds `key`; others: true.
  virtual bool has(const char* key) { (void)key; return true; }
  /// True while reading from a file (values may change under describe()).
  virtual bool reading() const { return false; }
  /// A value that cannot be accepted: throws ConfigError at `key` of the
  /// current map ("" = the map itself).
  [[noreturn]] virtual void fail(const char* key, const std::string& what);

  /// An enum through its spellings: toString(E) (found by ADL) names each
  /// of `all`, the values a user may give.
  template <class E>
  void enumeration(const FieldInfo& info, E& value, const std::vector<E>& all) {
    member(&value, sizeof value);
    std::string name = toString(value);
    std::vector<std::string> allowed;
    for (const E& e : all) allowed.push_back(toString(e));
    choice(info, name, allowed);
    for (const E& e : all)
      if (toString(e) == name) value = e;
  }
  /// A list of enums through their spellings (see enumeration()).
  template <class E>
  void enumerations(const FieldInfo& info, std::vector<E>& values, const std::vector<E>& all) {
    member(&values, sizeof values);
    std::vector<std::string> names, allowed;
    for (const E& e : all) allowed.push_back(toString(e));
    for (const E& x : values) names.push_back(toString(x));
    choices(info, names, allowed);
    values.clear();
    for (const auto& n : names)
      for (const E& e : all)
        if (toString(e) == n) values.push_back(e);
  }
  /// A list of structs, each described by `describe_item`.
  template <class T, class Describe>
  void items(const FieldInfo& info, std::vector<T>& list, const Describe& describe_item) {
    member(&list, sizeof list);
    std::size_t n = list.size();
    sequence(info, n, [&](std::size_t i, FieldVisitor& v) {
      if (i == 0 && v.reading()) list.assign(n, T{});  // a list read replaces the old one
      if (list.size() <= i) list.resize(i + 1);
      describe_item(v, list[i]);
    });
    if (list.size() != n) list.resize(n);
  }
};

/// A whole configuration's describe function.
using Describe = std::function<void(FieldVisitor&)>;

/// The fields `describe` visits whose values lie outside their ranges, as
/// "key: must be >= 0, got -1; " per field (dotted keys below the struct, in
/// schema order); "" when every value is valid. The generated part of every
/// validate().
std::string rangeProblems(const Describe& describe);

/// rangeProblems of one options struct, through its describe() (found by
/// argument-dependent lookup) on a copy: `options` is only read.
template <class Options>
std::string rangeProblemsOf(const Options& options) {
  Options copy = options;
  return rangeProblems(Describe([&](FieldVisitor& v) { describe(v, copy); }));
}

/// Fails a read (FieldVisitor::fail: the file, the line, the section) with
/// the first of validate()'s problems, "key: what; ...", under its key; does
/// nothing when there are none.
void failOnFirstProblem(FieldVisitor& v, const std::string& problems);

/// "key: what; key: what; " of one section's validate() with "section." put
/// before every key.
std::string inSection(const std::string& section, const std::string& problems);

}  // namespace celc
