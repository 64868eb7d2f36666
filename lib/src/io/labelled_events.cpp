#include "celc/io/labelled_events.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "celc/core/text.hpp"

namespace celc {
namespace {

/// The comma-separated fields of a line, each without surrounding blanks.
std::vector<std::string> splitComma(const std::string& line) {
  std::vector<std::string> out = splitList(line, ',');
  for (std::string& field : out) field = trimBlanks(field);
  return out;
}

template <typename T>
T parseField(const std::string& text, const std::string& where, const char* name) {
  T value{};
  const char* b = text.data();
  const char* e = b + text.size();
  const auto [ptr, ec] = std::from_chars(b, e, value);
  if (ec != std::errc() || ptr != e || text.empty())
    throw std::runtime_error(where + ": field '" + name + "' is not a number: '" + text + "'");
  if constexpr (std::is_floating_point_v<T>)
    if (!std::isfinite(value))
      throw std::runtime_error(where + ": field '" + name + "' is not finite: '" + text + "'");
  return value;
}

}  // namespace

std::vector<LabelledEvent> readLabelledEvents(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  size_t line_no = 0;
  std::vector<LabelledEvent> events;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    const std::string t = trimBlanks(line);
    if (t.empty() || t[0] == '#') continue;
    const auto f = splitComma(t);
    if (!header_seen) {
      if (f.size() != 4 || f[0] != "t" || f[1] != "x" || f[2] != "y" || f[3] != "cluster")
        throw std::runtime_error(where + ": expected the header 't,x,y,cluster', got '" + t + "'");
      header_seen = true;
      continue;
    }
    if (f.size() != 4)
      throw std::runtime_error(where + ": expected 4 fields (t,x,y,cluster), got " +
                               std::to_string(f.size()));
    events.push_back({parseField<double>(f[0], where, "t"), parseField<double>(f[1], where, "x"),
                      parseField<double>(f[2], where, "y"),
                      parseField<int>(f[3], where, "cluster")});
  }
  if (!header_seen) throw std::runtime_error(path + ": empty file (expected the header 't,x,y,cluster')");
  return events;
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot write (temporary " + tmp + ")");
    out << content;
    out.flush();
    if (!out) throw std::runtime_error(path + ": write failed");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename the temporary file into place");
  }
}

}  // namespace celc
