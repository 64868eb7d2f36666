#pragma once
// Private helpers for the text readers: chunked line reading (no iostreams) and
// number parsing with std::from_chars.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc::detail {

/// Reads a file in large blocks and hands out lines (without "\n" / "\r\n").
/// A missing final newline is fine. Lines longer than the buffer are an error.
class LineReader {
 public:
  explicit LineReader(const std::string& path, std::size_t buffer_bytes = std::size_t(4) << 20);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;
  /// Next line; false at end of file. line() numbers from 1.
  bool next(std::string_view& line);
  std::uint64_t lineNumber() const { return line_no_; }
  const std::string& path() const { return path_; }
  [[noreturn]] void fail(const std::string& what) const;

 private:
  bool refill();
  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<char> buf_;
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false;
  std::uint64_t line_no_ = 0;
};

inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

/// Splits on spaces, tabs and commas into at most `max` fields; returns the count
/// (max + 1 when there are more fields than max).
inline std::size_t splitFields(std::string_view line, std::string_view* out, std::size_t max) {
  const char* p = line.data();
  const char* e = p + line.size();
  std::size_t n = 0;
  while (true) {
    while (p < e && isSpace(*p)) ++p;
    if (p >= e) break;
    const char* s = p;
    while (p < e && !isSpace(*p)) ++p;
    if (n == max) return max + 1;
    out[n++] = std::string_view(s, std::size_t(p - s));
  }
  return n;
}

inline bool parseDouble(std::string_view f, double& v) {
  const char* b = f.data();
  const char* e = b + f.size();
  if (b < e && *b == '+') ++b;
  auto r = std::from_chars(b, e, v);
  return r.ec == std::errc() && r.ptr == e;
}

inline bool parseInt(std::string_view f, long long& v) {
  const char* b = f.data();
  const char* e = b + f.size();
  if (b < e && *b == '+') ++b;
  auto r = std::from_chars(b, e, v);
  return r.ec == std::errc() && r.ptr == e;
}

/// True if the line is blank or a comment.
inline bool isBlank(std::string_view line) {
  for (char c : line)
    if (!isSpace(c)) return false;
  return true;
}

/// Lower-case names of a header line ("# id timestamp x y polarity" or "t,x,y,p").
std::vector<std::string> headerNames(std::string_view line);
/// True when the first field does not parse as a number (a header line without '#').
bool looksLikeHeader(std::string_view line);

}  // namespace celc::detail
