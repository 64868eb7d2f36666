#pragma once
// Shared by the libFuzzer harnesses: the input goes to a file with a fixed name
// (the readers take paths), and every error a reader or loader throws must keep
// the contract of docs/formats.md: one printable line that names the file. Any other
// exception (std::bad_alloc, a library's own exception, ...) is a finding: the
// harness aborts so that libFuzzer records the input.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

#include "celc/core/fields.hpp"
#include "celc/io/event_reader.hpp"

namespace celc::fuzz {

/// A per-process directory for the input files: in /dev/shm (tmpfs) when there
/// is one, so that writing each input costs no disk journal, else in the
/// temporary directory. Made once per process, removed at its exit.
inline const std::string& workDir() {
  static const std::string dir = [] {
    std::error_code ec;
    const std::filesystem::path shm = "/dev/shm";
    const auto base = std::filesystem::is_directory(shm, ec) ? shm : std::filesystem::temp_directory_path();
    const auto d = base / ("celc_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  static const bool cleanup = [] {
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(workDir(), ec);
    });
    return true;
  }();
  (void)cleanup;
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

/// Writes the input after `magic` (dropped from the input first when it starts
/// with it: seeds are whole files) and returns the path, so that every input
/// reaches the reader of that format.
inline std::string writeWithMagic(const std::string& name, const std::string& magic, const std::uint8_t* data,
                                  std::size_t size) {
  if (size >= magic.size() && std::memcmp(data, magic.data(), magic.size()) == 0) {
    data += magic.size();
    size -= magic.size();
  }
  std::string bytes = magic;
  bytes.append(reinterpret_cast<const char*>(data), size);
  return writeInput(name, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
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
/// keeps the contract, anything else aborts. True when `body` threw nothing.
inline bool expectCleanErrors(const std::string& path, const std::function<void()>& body) {
  try {
    body();
    return true;
  } catch (const IoError& e) {
    checkMessage(e.what(), path);
  } catch (const ConfigError& e) {
    checkMessage(e.what(), path);
  } catch (const std::bad_alloc& e) {
    finding("std::bad_alloc", e.what());
  } catch (const std::exception& e) {
    finding("unexpected exception type", e.what());
  }
  return false;
}

/// Opens `path` through format detection and reads every event, the IMU and
/// the poses; then, with `seek_to`, opens it again, seeks there and reads one
/// batch (the readers that can seek). True when the first pass threw nothing.
inline bool readEverything(const std::string& path, std::optional<double> seek_to = std::nullopt) {
  const bool ok = expectCleanErrors(path, [&] {
    auto reader = openEventSource(path);
    std::vector<Event> batch;
    while (reader->next(batch, 1000)) {
    }
    (void)reader->readImu();
    (void)reader->readPoses();
  });
  if (seek_to) {
    expectCleanErrors(path, [&] {
      auto reader = openEventSource(path);
      if (reader->seekTime(*seek_to)) {
        std::vector<Event> batch;
        (void)reader->next(batch, 1000);
      }
    });
  }
  return ok;
}

}  // namespace celc::fuzz
