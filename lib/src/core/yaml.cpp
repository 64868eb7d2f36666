#include "celc/core/yaml.hpp"
#include "celc/core/text.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace celc {

namespace {
/// One printable line: bytes outside printable ASCII (control bytes, line
/// breaks, invalid or non-ASCII UTF-8 from a hostile file) as <0xNN>.
std::string printable(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "<0x%02X>", c);
      out += buf;
    }
  }
  return out;
}

std::string placeText(const std::string& origin, int line, const std::string& key,
                      const std::string& what) {
  std::string s = origin;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": ";
  if (!key.empty()) s += "key '" + printable(key) + "': ";
  return s + printable(what);
}
}  // namespace

ConfigError::ConfigError(std::string origin_, int line_, std::string key_, const std::string& what)
    : std::runtime_error(placeText(origin_, line_, key_, what)),
      origin(std::move(origin_)),
      line(line_),
      key(std::move(key_)) {}

ConfigError::ConfigError(const std::string& message) : std::runtime_error(printable(message)) {}

void FieldVisitor::fail(const char* key, const std::string& what) {
  throw ConfigError("", 0, key, what);
}

namespace {

// ---- values as YAML text ----------------------------------------------------

std::string numberText(double x) {
  if (std::isnan(x)) return ".nan";
  if (std::isinf(x)) return x > 0 ? ".inf" : "-.inf";
  std::string s = roundTripText(x);
  // Keep it a float to the eye: "2" -> "2.0" (YAML reads both).
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string stringText(const std::string& s) {
  YAML::Emitter e;
  e << s;
  return e.c_str();
}

std::string listText(std::size_t n, const std::function<std::string(std::size_t)>& one) {
  std::string s = "[";
  for (std::size_t i = 0; i < n; ++i) s += (i ? ", " : "") + one(i);
  return s + "]";
}

/// The writer's and the lister's base: every value as its YAML text, handed
/// to value(); sections and sequences stay theirs.
class TextVisitor : public FieldVisitor {
 public:
  void field(const FieldInfo& i, bool& v) override { value(i, v ? "true" : "false"); }
  void field(const FieldInfo& i, int& v) override { value(i, std::to_string(v)); }
  void field(const FieldInfo& i, unsigned& v) override { value(i, std::to_string(v)); }
  void field(const FieldInfo& i, long& v) override { value(i, std::to_string(v)); }
  void field(const FieldInfo& i, unsigned long& v) override { value(i, std::to_string(v)); }
  void field(const FieldInfo& i, double& v) override { value(i, numberText(v)); }
  void field(const FieldInfo& i, std::string& v) override { value(i, stringText(v)); }
  void field(const FieldInfo& i, Vec2& v) override { value(i, numbers(v.data(), 2)); }
  void field(const FieldInfo& i, Vec3& v) override { value(i, numbers(v.data(), 3)); }
  void field(const FieldInfo& i, std::vector<double>& v, const std::vector<std::size_t>&) override {
    value(i, numbers(v.data(), v.size()));
  }
  void choice(const FieldInfo& i, std::string& v, const std::vector<std::string>& allowed) override {
    value(i, v, allowed);
  }
  void choices(const FieldInfo& i, std::vector<std::string>& v, const std::vector<std::string>& allowed) override {
    value(i, listText(v.size(), [&](std::size_t k) { return v[k]; }), allowed);
  }

 protected:
  virtual void value(const FieldInfo& info, const std::string& text,
                     const std::vector<std::string>& allowed = {}) = 0;

 private:
  static std::string numbers(const double* x, std::size_t n) {
    return listText(n, [&](std::size_t k) { return numberText(x[k]); });
  }
};

std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string shown(const YAML::Node& n) {
  if (n.IsScalar()) {
    std::string s = n.Scalar().substr(0, 60);
    for (char& c : s)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    return "'" + s + "'";
  }
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "nothing";
}

int lineOf(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.line >= 0 ? m.line + 1 : 0;
}

// ---- strict scalar parsing ----------------------------------------------------

bool parseInteger(const std::string& s, long& out) {
  const char* b = s.data();
  const char* e = b + s.size();
  if (b != e && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, out);
  return ec == std::errc() && p == e && b != e;
}

bool parseUnsigned(const std::string& s, unsigned long& out) {
  const char* b = s.data();
  const char* e = b + s.size();
  if (b != e && *b == '+') ++b;
  if (b == e || *b == '-') return false;
  auto [p, ec] = std::from_chars(b, e, out);
  return ec == std::errc() && p == e;
}

bool parseReal(const std::string& s, double& out) {
  static const std::map<std::string, double> special = {
      {".inf", INFINITY}, {".Inf", INFINITY}, {".INF", INFINITY}, {"+.inf", INFINITY},
      {"+.Inf", INFINITY}, {"+.INF", INFINITY}, {"-.inf", -INFINITY}, {"-.Inf", -INFINITY},
      {"-.INF", -INFINITY}, {"inf", INFINITY}, {"-inf", -INFINITY}};
  if (const auto it = special.find(s); it != special.end()) {
    out = it->second;
    return true;
  }
  if (s.empty()) return false;
  // Decimal numbers only: no hex, no "nan", no trailing text.
  for (char c : s)
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == 'e' || c == 'E' ||
          c == '+' || c == '-'))
      return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno != ERANGE;
}

// ---- the reader ---------------------------------------------------------------

class Reader final : public FieldVisitor {
 public:
  Reader(const YAML::Node& map, const std::string& origin, std::string path)
      : map_(map), origin_(origin), path_(std::move(path)) {
    if (!map_ || map_.IsNull()) return;
    if (!map_.IsMap()) throw ConfigError(origin_, lineOf(map_), path_, "expected a map of keys, got " + shown(map_));
    std::map<std::string, int> first_line;
    for (const auto& kv : map_) {
      if (!kv.first.IsScalar())
        throw ConfigError(origin_, lineOf(kv.first), path_, "keys must be names, got " + shown(kv.first));
      const std::string k = kv.first.Scalar();
      const auto [it, fresh] = first_line.emplace(k, lineOf(kv.first));
      if (!fresh)
        throw ConfigError(origin_, lineOf(kv.first), join(path_, k),
                          "given twice (first at line " + std::to_string(it->second) + ")");
    }
  }

  bool reading() const override { return true; }

  void field(const FieldInfo& i, bool& v) override {
    scalar(i, [&](const std::string& s) {
      static const std::set<std::string> yes = {"true", "True", "TRUE", "yes", "Yes", "on", "On"};
      static const std::set<std::string> no = {"false", "False", "FALSE", "no", "No", "off", "Off"};
      if (yes.count(s)) v = true;
      else if (no.count(s)) v = false;
      else return false;
      return true;
    }, "true or false");
  }
  void field(const FieldInfo& i, int& v) override { integer(i, v); }
  void field(const FieldInfo& i, unsigned& v) override { integer(i, v); }
  void field(const FieldInfo& i, long& v) override { integer(i, v); }
  void field(const FieldInfo& i, unsigned long& v) override { integer(i, v); }
  void field(const FieldInfo& i, double& v) override {
    scalar(i, [&](const std::string& s) { return parseReal(s, v); }, "a number");
  }
  void field(const FieldInfo& i, std::string& v) override {
    scalar(i, [&](const std::string& s) { v = s; return true; }, "a string");
  }
  void field(const FieldInfo& i, Vec2& v) override {
    std::vector<double> x{v.x(), v.y()};
    field(i, x, {2});
    v = Vec2(x[0], x[1]);
  }
  void field(const FieldInfo& i, Vec3& v) override {
    std::vector<double> x{v.x(), v.y(), v.z()};
    field(i, x, {3});
    v = Vec3(x[0], x[1], x[2]);
  }
  void field(const FieldInfo& i, std::vector<double>& v, const std::vector<std::size_t>& sizes) override {
    const YAML::Node n = find(i.key);
    if (!n) return;
    std::string want;
    for (std::size_t s : sizes) want += (want.empty() ? "" : " or ") + std::to_string(s);
    const std::string expect = "expected a list of " + (want.empty() ? std::string() : want + " ") + "numbers";
    if (!n.IsSequence()) fail(i.key, expect + ", got " + shown(n));
    bool size_ok = sizes.empty();
    for (std::size_t s : sizes) size_ok |= n.size() == s;
    if (!size_ok) fail(i.key, expect + ", found " + std::to_string(n.size()));
    std::vector<double> out;
    for (std::size_t k = 0; k < n.size(); ++k) {
      double x = 0.0;
      if (!n[k].IsScalar() || !parseReal(n[k].Scalar(), x))
        throw ConfigError(origin_, lineOf(n[k]), join(path_, i.key) + "[" + std::to_string(k) + "]",
                          "expected a number, got " + shown(n[k]));
      out.push_back(x);
    }
    v = out;
  }
  void choice(const FieldInfo& i, std::string& v, const std::vector<std::string>& allowed) override {
    const YAML::Node n = find(i.key);
    if (!n) return;
    if (!n.IsScalar()) fail(i.key, "expected one of " + listOf(allowed) + ", got " + shown(n));
    v = checked(i.key, n, allowed);
  }
  void choices(const FieldInfo& i, std::vector<std::string>& v, const std::vector<std::string>& allowed) override {
    const YAML::Node n = find(i.key);
    if (!n) return;
    if (!n.IsSequence()) fail(i.key, "expected a list of " + listOf(allowed) + ", got " + shown(n));
    std::vector<std::string> out;
    for (std::size_t k = 0; k < n.size(); ++k) {
      if (!n[k].IsScalar()) fail(i.key, "expected names, got " + shown(n[k]));
      out.push_back(checked(i.key, n[k], allowed));
    }
    v = out;
  }
  void section(const FieldInfo& i, const std::function<void(FieldVisitor&)>& body) override {
    Reader sub(find(i.key), origin_, join(path_, i.key));
    body(sub);
    sub.finish();
  }
  void sequence(const FieldInfo& i, std::size_t& count,
                const std::function<void(std::size_t, FieldVisitor&)>& item) override {
    const YAML::Node n = find(i.key);
    if (!n) return;
    if (n.IsNull()) {
      count = 0;
      return;
    }
    if (!n.IsSequence()) fail(i.key, "expected a list, got " + shown(n));
    count = n.size();
    for (std::size_t k = 0; k < count; ++k) {
      const std::string path = join(path_, i.key) + "[" + std::to_string(k) + "]";
      if (!n[k].IsMap()) throw ConfigError(origin_, lineOf(n[k]), path, "expected a map, got " + shown(n[k]));
      Reader sub(n[k], origin_, path);
      item(k, sub);
      sub.finish();
    }
  }
  bool has(const char* key) override { return static_cast<bool>(find(key, false)); }
  void require(const char* key) override {
    if (!find(key, false)) fail("", "missing key '" + join(path_, key) + "'");
  }
  [[noreturn]] void fail(const char* key, const std::string& what) override {
    const std::string k = key;
    const YAML::Node n = k.empty() ? YAML::Node(YAML::NodeType::Undefined) : find(key, false);
    const int line = n ? lineOf(n) : (map_ ? lineOf(map_) : 0);
    throw ConfigError(origin_, line, k.empty() ? path_ : join(path_, k), what);
  }

  /// Unknown keys: the ones describe() never asked for.
  void finish() const {
    if (!map_ || !map_.IsMap()) return;
    for (const auto& kv : map_) {
      const std::string k = kv.first.Scalar();
      if (visited_.count(k)) continue;
      std::vector<std::string> allowed(order_.begin(), order_.end());
      throw ConfigError(origin_, lineOf(kv.first), "",
                        "unknown key '" + printable(join(path_, k)) + "'" +
                            (allowed.empty() ? std::string() : " (allowed here: " + listOf(allowed) + ")"));
    }
  }

 private:
  YAML::Node find(const char* key, bool mark = true) {
    if (mark && visited_.insert(key).second) order_.push_back(key);
    if (!map_ || !map_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& m = map_;  // const: a lookup never inserts; absent -> undefined (false)
    return m[key];
  }

  template <class Parse>
  void scalar(const FieldInfo& i, const Parse& parse, const char* type) {
    const YAML::Node n = find(i.key);
    if (!n) return;
    if (!n.IsScalar() || !parse(n.Scalar())) fail(i.key, std::string("expected ") + type + ", got " + shown(n));
  }

  template <class T>
  void integer(const FieldInfo& i, T& v) {
    scalar(i, [&](const std::string& s) {
      if constexpr (std::is_signed_v<T>) {
        long x = 0;
        if (!parseInteger(s, x) || x < std::numeric_limits<T>::min() || x > std::numeric_limits<T>::max())
          return false;
        v = static_cast<T>(x);
      } else {
        unsigned long x = 0;
        if (!parseUnsigned(s, x) || x > std::numeric_limits<T>::max()) return false;
        v = static_cast<T>(x);
      }
      return true;
    }, std::is_signed_v<T> ? (sizeof(T) == 4 ? "an integer (32 bit)" : "an integer")
                           : (sizeof(T) == 4 ? "a non-negative integer (32 bit)" : "a non-negative integer"));
  }

  std::string checked(const char* key, const YAML::Node& n, const std::vector<std::string>& allowed) {
    for (const auto& a : allowed)
      if (n.Scalar() == a) return a;
    throw ConfigError(origin_, lineOf(n), join(path_, key),
                      "expected one of " + listOf(allowed) + ", got " + shown(n));
  }

  static std::string listOf(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
  }

  YAML::Node map_;
  std::string origin_;
  std::string path_;
  std::set<std::string> visited_;
  std::vector<std::string> order_;
};

// ---- the writer ----------------------------------------------------------------

class Writer final : public TextVisitor {
 public:
  Writer(std::ostringstream& out, std::string indent, bool comments)
      : out_(out), indent_(std::move(indent)), comments_(comments) {}

  void section(const FieldInfo& i, const std::function<void(FieldVisitor&)>& body) override {
    std::ostringstream inner;
    Writer sub(inner, indent_ + "  ", comments_);
    body(sub);
    if (inner.str().empty()) {
      value(i, "{}");
      return;
    }
    value(i, "");
    out_ << inner.str();
  }
  void sequence(const FieldInfo& i, std::size_t& count,
                const std::function<void(std::size_t, FieldVisitor&)>& item) override {
    if (count == 0) {
      value(i, "[]");
      return;
    }
    value(i, "");
    for (std::size_t k = 0; k < count; ++k) {
      std::ostringstream inner;
      Writer sub(inner, indent_ + "    ", comments_);
      item(k, sub);
      std::string text = inner.str();
      if (text.empty()) text = indent_ + "    {}\n";
      text.replace(indent_.size(), 4, "  - ");  // the first line opens the item
      out_ << text;
    }
  }

 private:
  void value(const FieldInfo& i, const std::string& value, const std::vector<std::string>& allowed = {}) override {
    std::string text = indent_ + i.key + ":" + (value.empty() ? "" : " " + value);
    std::string note;
    if (comments_) {
      if (i.unit && *i.unit) note += std::string("[") + i.unit + "]";
      if (i.doc && *i.doc) note += (note.empty() ? "" : " ") + std::string(i.doc);
      if (!allowed.empty()) {
        std::string names;
        for (const auto& a : allowed) names += (names.empty() ? "" : " | ") + a;
        note += (note.empty() ? "" : " ") + std::string("(") + names + ")";
      }
    }
    if (!note.empty()) {
      if (text.size() < 34) text.resize(34, ' ');
      text += "  # " + note;
    }
    out_ << text << "\n";
  }

  std::ostringstream& out_;
  std::string indent_;
  bool comments_;
};

// ---- the lister ----------------------------------------------------------------

class Lister final : public TextVisitor {
 public:
  Lister(std::vector<FieldEntry>& out, std::string path) : out_(out), path_(std::move(path)) {}

  void section(const FieldInfo& i, const std::function<void(FieldVisitor&)>& body) override {
    Lister sub(out_, join(path_, i.key));
    body(sub);
  }
  void sequence(const FieldInfo& i, std::size_t& count,
                const std::function<void(std::size_t, FieldVisitor&)>& item) override {
    value(i, "[" + std::to_string(count) + " items]");
    for (std::size_t k = 0; k < count; ++k) {
      Lister sub(out_, join(path_, i.key) + "[" + std::to_string(k) + "]");
      item(k, sub);
    }
  }

 private:
  void value(const FieldInfo& i, const std::string& value, const std::vector<std::string>& allowed = {}) override {
    out_.push_back({join(path_, i.key), i.unit ? i.unit : "", i.doc ? i.doc : "", value, allowed, i.range.text()});
  }
  std::vector<FieldEntry>& out_;
  std::string path_;
};

}  // namespace

void readYaml(const std::string& text, const std::string& origin, const Describe& describe) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(origin, e.mark.line >= 0 ? e.mark.line + 1 : 0, "", "YAML syntax: " + e.msg);
  }
  if (root && !root.IsNull() && !root.IsMap())
    throw ConfigError(origin, lineOf(root), "", "expected a map of keys at the top level, got " + shown(root));
  Reader reader(root, origin, "");
  describe(reader);
  reader.finish();
}

void readYamlFile(const std::string& path, const Describe& describe) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, 0, "", "cannot open the file");
  // A configuration file is small: refuse anything that is clearly not one.
  constexpr std::streamoff kMaxBytes = 16 << 20;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size > kMaxBytes) throw ConfigError(path, 0, "", "larger than 16 MB: not a configuration file");
  in.seekg(0);
  std::stringstream ss;
  ss << in.rdbuf();
  readYaml(ss.str(), path, describe);
}

std::string writeYaml(const Describe& describe, const YamlWriteOptions& options) {
  std::ostringstream out;
  if (!options.header.empty()) {
    std::istringstream lines(options.header);
    for (std::string l; std::getline(lines, l);) out << (l.empty() ? "#" : "# " + l) << "\n";
  }
  Writer writer(out, "", options.comments);
  describe(writer);
  return out.str();
}

void applyAssignment(const std::string& assignment, const Describe& describe) {
  const std::string origin = "--set " + assignment;
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) throw ConfigError(origin, 0, "", "expected key.path=value");
  std::vector<std::string> parts;
  std::stringstream path(assignment.substr(0, eq));
  for (std::string part; std::getline(path, part, '.');) {
    if (part.empty() || part.find_first_of(" :#[]{}") != std::string::npos)
      throw ConfigError(origin, 0, "", "expected key.path=value with names between the dots");
    parts.push_back(part);
  }
  std::string yaml, indent;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    yaml += indent + parts[i] + ":" + (i + 1 == parts.size() ? " " + assignment.substr(eq + 1) + "\n" : "\n");
    indent += "  ";
  }
  readGeneratedYaml(yaml, origin, describe);
}

void readGeneratedYaml(const std::string& text, const std::string& origin, const Describe& describe) {
  try {
    readYaml(text, origin, describe);
  } catch (const ConfigError& e) {
    // Lines of the generated document mean nothing to the user.
    const std::string what = e.what();
    const std::string prefix = origin + ":" + std::to_string(e.line) + ": ";
    throw ConfigError(what.rfind(prefix, 0) == 0 ? origin + ": " + what.substr(prefix.size()) : what);
  }
}

std::vector<FieldEntry> listFields(const Describe& describe) {
  std::vector<FieldEntry> out;
  Lister lister(out, "");
  describe(lister);
  return out;
}

std::string fieldHelp(const Describe& describe, const std::string& dotted_key) {
  for (const FieldEntry& f : listFields(describe)) {
    if (f.key != dotted_key) continue;
    std::string s = f.doc;
    if (!f.unit.empty() && f.unit != "-") s += " [" + f.unit + "]";
    return s + " (YAML " + f.key + ", default " + f.value + ")";
  }
  throw std::logic_error("fieldHelp: no key '" + dotted_key + "' in the schema");
}

}  // namespace celc
