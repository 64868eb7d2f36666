#pragma once
// Internal: wall time of a method, for SolverResult::time_us.
#include <chrono>

namespace celc::detail {

using Clock = std::chrono::steady_clock;

/// Microseconds elapsed since `start`.
inline double microsecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

}  // namespace celc::detail
