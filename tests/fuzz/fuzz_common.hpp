#pragma once
// Shared by the libFuzzer harnesses: the input goes to a file with a fixed name
// (the readers take paths), and every error a reader or loader throws must keep
// the contract of docs/io.md: one printable line that names the file. Any other
// exception (std::bad_alloc, a library's own exception, ...) is a finding: the
// harness aborts so that libFuzzer records the input.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

#include "celc/core/fields.hpp"
#include "celc/io/event_reader.hpp"

namespace celc::fuzz {

/// A per-process directory for the input files.
inline const std::string& workDir() {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("celc_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir;
}

/// Writes the input to workDir()/name and returns the path.
inline std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::string path = workDir() + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

[[noreturn]] inline void finding(const char* kind, const std::string& what) {
  std::fprintf(stderr, "celc fuzz finding: %s: %s\n", kind, what.c_str());
  std::abort();
}

/// One line of printable ASCII that names `path`.
inline void checkMessage(const std::string& m, const std::string& path) {
  for (char c : m) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7F) finding("message with a raw byte", m);
  }
  if (m.find(path) == std::string::npos) finding("message without the file name", m);
}

/// Runs `body`; the errors of the bad-input policy are fine when their message
/// keeps the contract, anything else aborts.
inline void expectCleanErrors(const std::string& path, const std::function<void()>& body) {
  try {
    body();
  } catch (const IoError& e) {
    checkMessage(e.what(), path);
  } catch (const ConfigError& e) {
    checkMessage(e.what(), path);
  } catch (const std::bad_alloc& e) {
    finding("std::bad_alloc", e.what());
  } catch (const std::exception& e) {
    finding("unexpected exception type", e.what());
  }
}

}  // namespace celc::fuzz
