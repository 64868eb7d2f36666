#pragma once
/// \file window_source.hpp
/// Cuts any EventReader into consecutive windows, reading incrementally so that
/// memory is bounded by the window (plus one read batch), not by the file.
///  - by count: N events per window (the paper's choice); the window's time span
///    is [t of its first event, t of its last event];
///  - by duration: [t0, t0 + S) half-open, t0 starting at the first event (or t_start).
/// Overlap: a fraction in [0, 1) of the window shared with the next one
/// (step = (1 - overlap) * N events, or (1 - overlap) * S seconds).
/// Time range: events outside [t_start, t_end) are skipped; readers that can
/// seek (AEDAT 4.0 with a data table) jump to t_start.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/io/event_reader.hpp"

namespace celc {

struct WindowOptions {
  std::size_t events_per_window = 0;  ///< N > 0: windows by event count
  double seconds_per_window = 0.0;    ///< S > 0: windows by duration [s] (exactly one of N, S)
  double overlap = 0.0;               ///< [0, 1)
  double t_start = -std::numeric_limits<double>::infinity();  ///< [s]
  double t_end = std::numeric_limits<double>::infinity();     ///< [s], exclusive
  std::size_t read_batch = 65536;     ///< events pulled from the reader at a time
  /// Emit the last, incomplete window (fewer than N events / cut by the file's end).
  bool keep_partial = false;
  std::string validate() const;
};
/// The schema of the `windows:` section (core/fields.hpp).
void describe(FieldVisitor& v, WindowOptions& options);


struct EventWindow {
  std::uint64_t index = 0;
  double t0 = 0.0, t1 = 0.0;  ///< [s]; count windows: first and last event times
  std::vector<Event> events;
};

class WindowSource {
 public:
  /// Throws std::invalid_argument when the options are invalid. The reader must outlive the source.
  WindowSource(EventReader& reader, const WindowOptions& options);
  /// Next window; false when no (complete, unless keep_partial) window remains.
  bool next(EventWindow& window);
  /// Largest number of events held at once so far (the memory bound).
  std::size_t peakBuffered() const { return peak_; }

 private:
  bool pull();  ///< appends one batch within the time range; false at the end
  EventReader& reader_;
  WindowOptions o_;
  std::deque<Event> buf_;
  std::vector<Event> batch_;
  bool eof_ = false;
  bool past_end_ = false;  ///< an event at or after t_end was seen
  bool started_ = false;
  double next_t0_ = 0.0;
  std::uint64_t index_ = 0;
  std::size_t peak_ = 0;
};

}  // namespace celc
