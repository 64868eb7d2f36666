#include "io/text_parse.hpp"

#include <cctype>
#include <cerrno>
#include <cstring>
#include <sys/stat.h>

#include <algorithm>

namespace celc::detail {

LineReader::LineReader(const std::string& path, std::size_t buffer_bytes) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw IoError(path + ": cannot open: " + std::strerror(errno));
  // A small file needs no 4 MB block: size + 1 holds all of it (so the
  // line-length limit is never reached earlier than with the full block).
  struct stat st {};
  if (::fstat(::fileno(file_), &st) == 0 && S_ISREG(st.st_mode))
    buffer_bytes = std::min<std::size_t>(buffer_bytes, std::max<std::size_t>(std::size_t(st.st_size) + 1, 65536));
  buf_.resize(buffer_bytes);
}

LineReader::~LineReader() {
  if (file_) std::fclose(file_);
}

void LineReader::fail(const std::string& what) const {
  throw IoError(path_ + ": line " + std::to_string(line_no_) + ": " + printable(what, 400));
}

bool LineReader::refill() {
  if (eof_) return false;
  if (begin_ > 0) {
    std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ == buf_.size()) {
    ++line_no_;
    fail("line longer than " + std::to_string(buf_.size()) + " bytes");
  }
  std::size_t got = std::fread(buf_.data() + end_, 1, buf_.size() - end_, file_);
  if (got == 0) {
    if (std::ferror(file_)) throw IoError(path_ + ": read error: " + std::strerror(errno));
    eof_ = true;
    return false;
  }
  end_ += got;
  return true;
}

bool LineReader::next(std::string_view& line) {
  while (true) {
    const char* s = buf_.data() + begin_;
    const void* nl = std::memchr(s, '\n', end_ - begin_);
    if (nl) {
      const char* n = static_cast<const char*>(nl);
      std::size_t len = std::size_t(n - s);
      if (len > 0 && s[len - 1] == '\r') --len;
      line = std::string_view(s, len);
      begin_ += std::size_t(n - s) + 1;
      ++line_no_;
      return true;
    }
    if (!refill()) {
      if (begin_ == end_) return false;
      // last line without a final newline
      const char* s2 = buf_.data() + begin_;
      std::size_t len = end_ - begin_;
      if (len > 0 && s2[len - 1] == '\r') --len;
      line = std::string_view(s2, len);
      begin_ = end_;
      ++line_no_;
      return true;
    }
  }
}

std::vector<std::string> headerNames(std::string_view line) {
  std::vector<std::string> names;
  std::string cur;
  for (char c : line) {
    if (c == '#' || isSpace(c) || c == ';' || c == '[' || c == ']' || c == '(' || c == ')') {
      if (!cur.empty()) names.push_back(cur), cur.clear();
    } else {
      cur.push_back(char(std::tolower(static_cast<unsigned char>(c))));
    }
  }
  if (!cur.empty()) names.push_back(cur);
  return names;
}

bool looksLikeHeader(std::string_view line) {
  std::string_view f[2];
  if (splitFields(line, f, 1) == 0) return false;
  double v;
  return !parseDouble(f[0], v) && std::isalpha(static_cast<unsigned char>(f[0][0]));
}

}  // namespace celc::detail
