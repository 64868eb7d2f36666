#include "celc/core/text.hpp"

#include <cstdio>
#include <cstdlib>

namespace celc {

std::vector<std::string> splitList(std::string_view text, char separator) {
  std::vector<std::string> fields;
  if (text.empty()) return fields;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t end = text.find(separator, begin);
    fields.emplace_back(text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin));
    if (end == std::string_view::npos) return fields;
    begin = end + 1;
  }
}

std::string trimBlanks(std::string_view text) {
  const std::size_t b = text.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const std::size_t e = text.find_last_not_of(" \t\r");
  return std::string(text.substr(b, e - b + 1));
}

std::string byteCountText(double bytes) {
  if (!(bytes >= 0.0)) return "an invalid number of";
  if (!(bytes < 18446744073709551616.0)) return "more than 2^64";
  return std::to_string(static_cast<unsigned long long>(bytes));
}

std::string roundTripText(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", x);
  if (std::strtod(buf, nullptr) != x) std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace celc
