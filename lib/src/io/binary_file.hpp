#pragma once
// Private helpers for the binary readers: a bounds-aware file, little/big-endian
// loads, and the DAVIS chip table.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc::detail {

class BinFile {
 public:
  explicit BinFile(const std::string& path);
  ~BinFile();
  BinFile(const BinFile&) = delete;
  BinFile& operator=(const BinFile&) = delete;
  std::uint64_t size() const { return size_; }
  std::uint64_t tell() const { return pos_; }
  void seek(std::uint64_t pos);
  /// Reads up to n bytes at the current position; returns the count.
  std::size_t read(void* dst, std::size_t n);
  /// Reads exactly n bytes or throws "truncated at byte ...".
  void readExact(void* dst, std::size_t n, const char* what);
  /// Reads one line (up to '\n', included) of at most max bytes; false at EOF.
  bool readLine(std::string& line, std::size_t max);
  const std::string& path() const { return path_; }
  [[noreturn]] void fail(std::uint64_t byte, const std::string& what) const;

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
  std::uint64_t size_ = 0, pos_ = 0;
};

inline std::uint32_t loadBE32(const unsigned char* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
         std::uint32_t(p[3]);
}
template <typename T>
inline T loadLE(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // the library assumes a little-endian host (checked in event_reader.cpp)
  return v;
}

/// Sensor size from a chip / camera name (DAVIS240*, DAVIS346*, DAVIS128, DVS128,
/// DAVIS640, DVXplorer*); false when unknown.
bool sensorSizeFromChip(const std::string& name, int& width, int& height);

constexpr double kGravity = 9.80665;  ///< [m/s^2 per g]
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

}  // namespace celc::detail
