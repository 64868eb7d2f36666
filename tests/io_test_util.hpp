#pragma once
// Helpers shared by the io tests: a per-test temporary directory, synthetic
// recordings with a fixed seed, raw file editing for corruption cases.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc::test {

/// A fresh directory under the system temp dir, removed at destruction.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // one folder: a parameterised test's names hold '/' ("Datasets/Suite", "Test/param")
    std::string name = info ? std::string(info->test_suite_name()) + "_" + info->name() : "x";
    std::replace(name.begin(), name.end(), '/', '_');
    dir_ = std::filesystem::temp_directory_path() / ("celc_io_" + std::to_string(::getpid()) + "_" + name);
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~TempDir() { std::filesystem::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

 private:
  std::filesystem::path dir_;
};

/// Time-ordered events on a width x height sensor, whole-microsecond times from t0 [s].
inline std::vector<Event> randomEvents(std::size_t n, int width, int height, unsigned seed, double t0 = 10.0) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> ux(0, width - 1), uy(0, height - 1), dt(0, 20), pol(0, 1);
  std::vector<Event> ev(n);
  long long t_us = (long long)(t0 * 1e6);
  for (auto& e : ev) {
    t_us += dt(rng);
    e.t = double(t_us) / 1e6;  // as the readers convert whole microseconds (correctly rounded)
    e.x = float(ux(rng));
    e.y = float(uy(rng));
    e.on = pol(rng) == 1;
  }
  return ev;
}

/// IMU at 1 kHz over [t0, t1): smooth gyro [rad/s] and accel [m/s^2] within +-4 g / +-500 deg/s.
inline std::vector<ImuSample> randomImu(double t0, double t1, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<ImuSample> imu;
  const long long a = (long long)std::ceil(t0 * 1e3), b = (long long)std::floor(t1 * 1e3);
  for (long long k = a; k < b; ++k) {
    ImuSample s;
    s.t = double(k) / 1e3;
    s.gyro = Vec3(u(rng), u(rng), u(rng)) * 3.0;
    s.accel = Vec3(u(rng), u(rng), u(rng)) * 20.0;
    imu.push_back(s);
  }
  return imu;
}

inline std::string readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
inline void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), std::streamsize(bytes.size()));
}

/// Overwrites the file at `path` with `bytes` from `offset` after the start of
/// `pattern` (at its only, first, or last of at least two places); false when
/// the pattern does not stand there that way.
enum class Place { Only, First, LastOfSeveral };
inline bool patchBytes(const std::string& path, const std::string& pattern, std::size_t offset, const std::string& bytes,
                       Place place = Place::Only) {
  std::string b = readBytes(path);
  const std::size_t first = b.find(pattern), last = b.rfind(pattern);
  if (first == std::string::npos || (place == Place::Only && first != last) ||
      (place == Place::LastOfSeveral && first == last))
    return false;
  b.replace((place == Place::LastOfSeveral ? last : first) + offset, bytes.size(), bytes);
  writeBytes(path, b);
  return true;
}
inline void putLE32(std::string& b, std::size_t at, std::int32_t v) { std::memcpy(&b[at], &v, 4); }
inline void putBE32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b[at + std::size_t(k)] = char((v >> (24 - 8 * k)) & 0xFF);
}

/// Printable ASCII on one line: what every message may contain.
inline void expectPrintable(const std::string& m) {
  for (char c : m) {
    const auto u = static_cast<unsigned char>(c);
    ASSERT_TRUE(u >= 0x20 && u < 0x7F) << "byte " << int(u) << " in message: " << m;
  }
}

/// The message of the IoError `f` throws ("" and a failure when it does not throw one).
template <class F>
std::string ioErrorOf(F&& f) {
  try {
    f();
  } catch (const IoError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an IoError: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return {};
}

inline ReaderOptions strictOptions() {
  ReaderOptions o;
  o.strict = true;
  return o;
}

/// Reads everything (events and IMU) from a source; throws what the reader throws.
inline std::size_t drain(const std::string& path, const ReaderOptions& o = {}) {
  auto r = openEventSource(path, o);
  std::size_t n = readAllEvents(*r).size();
  n += r->readImu().size();
  return n;
}

/// Expects an IoError whose message contains every fragment.
#define EXPECT_IO_ERROR(stmt, ...)                                                   \
  do {                                                                               \
    try {                                                                            \
      stmt;                                                                          \
      ADD_FAILURE() << "no IoError from " #stmt;                                     \
    } catch (const celc::IoError& e) {                                           \
      const std::string msg_ = e.what();                                             \
      for (const std::string& frag_ : std::vector<std::string>{__VA_ARGS__})                                \
        EXPECT_NE(msg_.find(frag_), std::string::npos) << "message: " << msg_ << "\nmissing: " << frag_; \
      EXPECT_EQ(msg_.find('\n'), std::string::npos) << "multi-line message: " << msg_; \
    }                                                                                \
  } while (0)

inline std::string sharedData(const std::string& rel) {
  return std::string(CELC_SOURCE_DIR) + "/../shared/data/" + rel;
}
#define SKIP_IF_NO_SHARED(path)                                                                     \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent (" << path                \
                                                   << "): conformance test needs ../shared/data"

}  // namespace celc::test
