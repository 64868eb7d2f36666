#pragma once
// Progress on stderr: a bar redrawn in place when stderr is a terminal,
// else a plain log line every 10%. Thread-safe; `--quiet` silences it.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace celc::app {

class Progress {
 public:
  Progress(std::string label, bool quiet)
      : label_(std::move(label)), quiet_(quiet), tty_(isatty(fileno(stderr)) != 0),
        start_(std::chrono::steady_clock::now()) {}

  /// done of total (total <= 0: unknown), and optionally events processed (rate shown).
  void update(int done, int total, std::uint64_t events = 0) {
    if (quiet_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = elapsed > 0 ? static_cast<double>(events) / elapsed : 0.0;
    std::string text;
    char buf[256];
    if (total > 0) {
      const double left = done > 0 ? elapsed * (total - done) / done : 0.0;
      const int width = 30, filled = width * std::min(done, total) / total;
      std::snprintf(buf, sizeof buf, "[%s%s] %d/%d  %.0f s left", std::string(static_cast<size_t>(filled), '#').c_str(),
                    std::string(static_cast<size_t>(width - filled), '.').c_str(), done, total, left);
    } else {
      std::snprintf(buf, sizeof buf, "%d windows", done);
    }
    text = buf;
    if (events > 0) {
      std::snprintf(buf, sizeof buf, "  %.2f M events/s", rate / 1e6);
      text += buf;
    }
    if (tty_) {
      std::fprintf(stderr, "\r%s %s ", label_.c_str(), text.c_str());
      drawn_ = true;
      if (total > 0 && done == total) finish();
    } else {
      // Plain log lines: every 10% of a known total, else every 10 s.
      const bool due = total > 0 ? (10 * done / total > last_decile_ || done == total)
                                 : elapsed - last_log_ >= 10.0;
      if (due) {
        if (total > 0) last_decile_ = 10 * done / total;
        last_log_ = elapsed;
        std::fprintf(stderr, "%s: %s (%.0f s elapsed)\n", label_.c_str(), text.c_str(), elapsed);
      }
    }
  }

  /// Ends the redrawn line (terminal only).
  void finish() {
    if (tty_ && drawn_ && !quiet_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  std::string label_;
  bool quiet_, tty_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  int last_decile_ = 0;
  double last_log_ = 0.0;
  bool drawn_ = false;
};

}  // namespace celc::app
