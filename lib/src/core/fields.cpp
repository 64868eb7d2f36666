// Field ranges and the validation generated from them (core/fields.hpp).
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "celc/core/fields.hpp"
#include "celc/core/text.hpp"

namespace celc {

namespace {

/// A bound or a value as the user would write it: "0", "0.5", "1e-10", "inf".
std::string numberText(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return roundTripText(x);
}

std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

/// A value that a describe() refuses itself (FieldVisitor::fail) while the
/// ranges are checked.
struct Refused {
  std::string key, what;
};

/// Checks every numeric field against its range; collects "key: ...; ".
class RangeChecker final : public FieldVisitor {
 public:
  RangeChecker(std::string& out, std::string path) : out_(out), path_(std::move(path)) {}

  void field(const FieldInfo& i, bool&) override { (void)i; }
  void field(const FieldInfo& i, int& v) override { check(i, static_cast<double>(v)); }
  void field(const FieldInfo& i, unsigned& v) override { check(i, static_cast<double>(v)); }
  void field(const FieldInfo& i, long& v) override { check(i, static_cast<double>(v)); }
  void field(const FieldInfo& i, unsigned long& v) override { check(i, static_cast<double>(v)); }
  void field(const FieldInfo& i, double& v) override { check(i, v); }
  void field(const FieldInfo& i, std::string&) override { (void)i; }
  void field(const FieldInfo& i, Vec2& v) override { checkAll(i, v.data(), 2); }
  void field(const FieldInfo& i, Vec3& v) override { checkAll(i, v.data(), 3); }
  void field(const FieldInfo& i, std::vector<double>& v, const std::vector<std::size_t>&) override {
    checkAll(i, v.data(), v.size());
  }
  void choice(const FieldInfo&, std::string&, const std::vector<std::string>&) override {}
  void choices(const FieldInfo&, std::vector<std::string>&, const std::vector<std::string>&) override {}
  void section(const FieldInfo& i, const std::function<void(FieldVisitor&)>& body) override {
    RangeChecker sub(out_, join(path_, i.key));
    body(sub);
  }
  void sequence(const FieldInfo& i, std::size_t& count,
                const std::function<void(std::size_t, FieldVisitor&)>& item) override {
    for (std::size_t k = 0; k < count; ++k) {
      RangeChecker sub(out_, join(path_, i.key) + "[" + std::to_string(k) + "]");
      item(k, sub);
    }
  }
  [[noreturn]] void fail(const char* key, const std::string& what) override {
    throw Refused{join(path_, key), what};
  }

 private:
  void check(const FieldInfo& i, double x) {
    if (!i.range.contains(x))
      out_ += join(path_, i.key) + ": must be " + wanted(i.range, x) + ", got " + numberText(x) + "; ";
  }
  void checkAll(const FieldInfo& i, const double* x, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k)
      if (!i.range.contains(x[k])) {
        out_ += join(path_, i.key) + ": every element must be " + wanted(i.range, x[k]) + ", got " +
                numberText(x[k]) + "; ";
        return;
      }
  }
  /// What the range asks of a value it refused: "finite and >= 0" for a value
  /// that is not finite.
  static std::string wanted(const Range& r, double x) {
    const std::string text = r.text();
    return std::isfinite(x) || text == "finite" ? text : "finite and " + text;
  }

  std::string& out_;
  std::string path_;
};

}  // namespace

bool Range::contains(double x) const {
  if (!checks()) return true;
  if (!std::isfinite(x)) return false;
  return (min_open ? x > min : x >= min) && (max_open ? x < max : x <= max);
}

std::string Range::text() const {
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  if (has_min && has_max)
    return "in " + std::string(min_open ? "(" : "[") + numberText(min) + ", " + numberText(max) +
           (max_open ? ")" : "]");
  if (has_min) return (min_open ? "> " : ">= ") + numberText(min);
  if (has_max) return (max_open ? "< " : "<= ") + numberText(max);
  return finite ? "finite" : "";
}

std::string rangeProblems(const Describe& describe) {
  std::string out;
  RangeChecker checker(out, "");
  try {
    describe(checker);
  } catch (const Refused& r) {
    out += (r.key.empty() ? "" : r.key + ": ") + r.what + "; ";
  }
  return out;
}

std::string inSection(const std::string& section, const std::string& problems) {
  std::string out;
  std::size_t at = 0;
  while (at < problems.size()) {
    std::size_t end = problems.find("; ", at);
    if (end == std::string::npos) end = problems.size();
    out += section + "." + problems.substr(at, end - at) + "; ";
    at = end + 2;
  }
  return out;
}

void failOnFirstProblem(FieldVisitor& v, const std::string& problems) {
  if (problems.empty()) return;
  const std::string first = problems.substr(0, problems.find("; "));
  const auto colon = first.find(": ");
  if (colon == std::string::npos) v.fail("", first);
  v.fail(first.substr(0, colon).c_str(), first.substr(colon + 2));
}

}  // namespace celc
