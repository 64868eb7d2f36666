#include "io/binary_file.hpp"

#include <algorithm>
#include <cerrno>
#include <sys/stat.h>

namespace celc::detail {

BinFile::BinFile(const std::string& path) : path_(path) {
  f_ = std::fopen(path.c_str(), "rb");
  if (!f_) throw IoError(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw IoError(path + ": cannot stat: " + std::strerror(errno));
  size_ = std::uint64_t(st.st_size);
}

BinFile::~BinFile() {
  if (f_) std::fclose(f_);
}

void BinFile::fail(std::uint64_t byte, const std::string& what) const {
  throw IoError(path_ + ": byte " + std::to_string(byte) + ": " + printable(what, 400));
}

void BinFile::seek(std::uint64_t pos) {
  if (pos > size_) fail(pos, "offset beyond the end of the file (" + std::to_string(size_) + " bytes)");
  if (fseeko(f_, off_t(pos), SEEK_SET) != 0) fail(pos, "cannot seek");
  pos_ = pos;
}

std::size_t BinFile::read(void* dst, std::size_t n) {
  std::size_t got = std::fread(dst, 1, n, f_);
  if (got < n && std::ferror(f_)) fail(pos_, std::string("read error: ") + std::strerror(errno));
  pos_ += got;
  return got;
}

void BinFile::readExact(void* dst, std::size_t n, const char* what) {
  std::uint64_t at = pos_;
  std::size_t got = read(dst, n);
  if (got != n)
    fail(at, std::string("truncated ") + what + ": needs " + std::to_string(n) + " bytes, " +
                 std::to_string(got) + " left");
}

bool BinFile::readLine(std::string& line, std::size_t max) {
  line.clear();
  int c;
  while ((c = std::fgetc(f_)) != EOF) {
    ++pos_;
    line.push_back(char(c));
    if (c == '\n') return true;
    if (line.size() >= max) return true;
  }
  return !line.empty();
}

bool sensorSizeFromChip(const std::string& name, int& width, int& height) {
  std::string n;
  for (char c : name) n.push_back(char(std::toupper(static_cast<unsigned char>(c))));
  struct Chip { const char* key; int w, h; };
  static const Chip chips[] = {{"DAVIS240", 240, 180}, {"DAVIS346", 346, 260}, {"DAVIS640", 640, 480},
                               {"DAVIS128", 128, 128}, {"DVS128", 128, 128},   {"DVXPLORER_LITE", 320, 240},
                               {"DVXPLORER", 640, 480}, {"DAVIS208", 208, 192}, {"CDAVIS", 640, 480}};
  for (const Chip& c : chips)
    if (n.find(c.key) != std::string::npos) {
      width = c.w;
      height = c.h;
      return true;
    }
  return false;
}

}  // namespace celc::detail
