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
/// Gaps (by duration): empty windows are returned across a gap, unless the gap
/// is longer than the reader's max_time_jump or spans more than
/// kMaxEmptyWindows windows; then the source jumps to the window holding the
/// next event (counted in gaps() / skippedWindows(), described in reports()),
/// so one far timestamp never makes it produce windows without bound.
#include <cstddef>
#include <cstdint>
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
  /// Emit the last, incomplete window (fewer than N events / cut by the file's
  /// end) whatever it holds (the same as partial_min_share = 0).
  bool keep_partial = false;
  /// Otherwise the last, incomplete window is emitted when it holds at least
  /// this share of a window: of N events (by count) or of S seconds, from t0
  /// to its last event (by duration). In [0, 1]; 1 emits complete windows only.
  /// Either way it must hold events that no earlier window held.
  double partial_min_share = 1.0;
  /// Upper bound on the windows per second of data [1/s]: a window policy
  /// that would exceed it is an error, not a run of millions of windows.
  /// By duration it is checked here (1 / step); by count, where it depends on
  /// the event rate, by the caller as windows arrive.
  double max_windows_per_second = 10000.0;
  /// Upper bound on the events of one window [events]: a window by duration
  /// (or one the parallax policy joins) that would hold more is an error
  /// naming its time, not gigabytes of memory (24 bytes per event).
  std::size_t max_events = 20000000;
  /// Why the options are unusable ("" = valid): "key: what; " per problem,
  /// keys as in the `windows:` section.
  std::string validate() const;
};
/// The schema of the `windows:` section (core/fields.hpp).
void describe(FieldVisitor& v, WindowOptions& options);


/// What became of the events after the last emitted window (see WindowSource::tail()).
struct WindowTail {
  std::size_t events = 0;  ///< events in no emitted window (0: the windows covered the data)
  double share = 0.0;      ///< the partial window's share of a full window (events or seconds)
  bool emitted = false;    ///< the partial window was emitted (events then counts what it held)
};

struct EventWindow {
  std::uint64_t index = 0;
  double t0 = 0.0, t1 = 0.0;  ///< [s]; count windows: first and last event times
  std::vector<Event> events;
};

class WindowSource {
 public:
  /// Most empty windows returned for one gap before the source skips it.
  static constexpr std::uint64_t kMaxEmptyWindows = 1000;
  /// Throws std::invalid_argument when the options are invalid. The reader must outlive the source.
  WindowSource(EventReader& reader, const WindowOptions& options);
  /// Next window; false when no window remains (complete, or partial with
  /// enough events: keep_partial, partial_min_share).
  bool next(EventWindow& window);
  /// Largest number of events held at once so far (the memory bound).
  std::size_t peakBuffered() const { return peak_; }
  const WindowOptions& options() const { return o_; }
  /// The error for a window [t0, t1) that holds more than options().max_events events.
  IoError tooManyEvents(double t0, double t1) const;
  /// After next() returned false: the last, partial window, emitted or not.
  const WindowTail& tail() const { return tail_; }
  /// Gaps skipped so far, the empty windows they would have made, and up to 20
  /// one-line descriptions ("FILE: no events in [a, b) s: N empty windows of S s skipped").
  std::uint64_t gaps() const { return gaps_; }
  std::uint64_t skippedWindows() const { return skipped_; }
  const std::vector<std::string>& reports() const { return reports_; }

 private:
  /// Appends one batch (at most `max` events) within the time range; false at the end.
  bool pull(std::size_t max);
  /// By duration: moves the time grid past a long gap before the event at t_next.
  void skipGap(double t_next, double S, double step);
  /// The buffered events: buf_[head_, buf_.size()).
  std::size_t buffered() const { return buf_.size() - head_; }
  const Event* begin() const { return buf_.data() + head_; }
  const Event* end() const { return buf_.data() + buf_.size(); }
  /// Drops the first n buffered events (moved out of the buffer's front only
  /// when they are more than the rest: each event moves at most once).
  void dropFront(std::size_t n);
  EventReader& reader_;
  WindowOptions o_;
  std::vector<Event> buf_;  ///< the read events, from head_ on; one contiguous block, no per-event copies
  std::size_t head_ = 0;
  std::vector<Event> batch_;
  bool eof_ = false;
  bool past_end_ = false;  ///< an event at or after t_end was seen
  bool started_ = false;
  double next_t0_ = 0.0;
  std::uint64_t index_ = 0;       ///< windows returned
  std::uint64_t step_index_ = 0;  ///< by duration: steps from next_t0_ to the current window
  std::size_t peak_ = 0;
  std::size_t covered_front_ = 0;  ///< by count: events at the buffer's front already in a window
  double covered_until_ = -std::numeric_limits<double>::infinity();  ///< by duration: end of the last window [s]
  WindowTail tail_;
  std::uint64_t gaps_ = 0, skipped_ = 0;
  std::vector<std::string> reports_;
};

}  // namespace celc
