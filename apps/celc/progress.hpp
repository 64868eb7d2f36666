#pragma once
// Progress on stderr: a bar redrawn in place when stderr is a terminal,
// else a plain log line every 10%. Thread-safe; `--quiet` silences it.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace celc::app {

class Progress {
 public:
  Progress(std::string label, bool quiet)
      : label_(std::move(label)), quiet_(quiet), tty_(isatty(fileno(stderr)) != 0),
        start_(std::chrono::steady_clock::now()) {}

  void update(int done, int total) {
    if (quiet_ || total <= 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double left = done > 0 ? elapsed * (total - done) / done : 0.0;
    if (tty_) {
      const int width = 30, filled = width * done / total;
      std::fprintf(stderr, "\r%s [%s%s] %d/%d  %.0f s left ", label_.c_str(),
                   std::string(static_cast<size_t>(filled), '#').c_str(),
                   std::string(static_cast<size_t>(width - filled), '.').c_str(), done, total, left);
      if (done == total) std::fprintf(stderr, "\n");
    } else {
      const int decile = 10 * done / total;
      if (decile > last_decile_ || done == total) {
        last_decile_ = decile;
        std::fprintf(stderr, "%s: %d/%d (%.0f s elapsed, %.0f s left)\n", label_.c_str(), done,
                     total, elapsed, left);
      }
    }
  }

 private:
  std::string label_;
  bool quiet_, tty_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  int last_decile_ = 0;
};

}  // namespace celc::app
