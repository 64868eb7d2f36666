#include "celc/io/window_source.hpp"
#include "celc/core/memory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace celc {

std::string WindowOptions::validate() const {
  std::ostringstream e;
  e.precision(6);
  e << rangeProblemsOf(*this);
  // The rules that tie fields together; each speaks only where its fields are in range.
  const bool seconds_ok = std::isfinite(seconds_per_window) && seconds_per_window >= 0.0;
  if (!seconds_ok)
    e << "seconds: must be finite and > 0 (0 = windows by events), got " << seconds_per_window << "; ";
  else if ((events_per_window > 0) == (seconds_per_window > 0.0))
    e << "events, seconds: give exactly one of events (> 0) and seconds (> 0); ";
  const bool overlap_ok = overlap >= 0.0 && overlap < 1.0;
  if (overlap_ok && events_per_window > 0 && std::size_t(std::floor((1.0 - overlap) * double(events_per_window))) < 1)
    e << "overlap: leaves a step of 0 events; ";
  if (seconds_ok && overlap_ok && seconds_per_window > 0.0 && max_windows_per_second > 0.0 &&
      std::isfinite(max_windows_per_second)) {
    // By duration the rate is known before reading: one window per step.
    const double per_second = 1.0 / ((1.0 - overlap) * seconds_per_window);
    if (!(per_second <= max_windows_per_second))
      e << "seconds: windows of " << seconds_per_window << " s (overlap " << overlap << ") make " << per_second
        << " windows per second of data, more than max_windows_per_second = " << max_windows_per_second << "; ";
  }
  if (std::isnan(t_start) || std::isnan(t_end) || !(t_end > t_start)) e << "t_start, t_end: need t_start < t_end; ";
  if (max_events >= 1 && events_per_window > max_events)
    e << "events: " << events_per_window << " per window, more than max_events = " << max_events << "; ";
  return e.str();
}

IoError WindowSource::tooManyEvents(double t0, double t1) const {
  char text[160];
  std::snprintf(text, sizeof text, ": the window [%.6f, %.6f) s holds more than windows.max_events = %zu events",
                t0, t1, o_.max_events);
  return IoError(detail::printable(reader_.path()) + text +
                 " (a burst of events at one time, or windows too long for the event rate; raise "
                 "windows.max_events or shorten the windows)");
}

WindowSource::WindowSource(EventReader& reader, const WindowOptions& options) : reader_(reader), o_(options) {
  const std::string err = o_.validate();
  if (!err.empty()) throw std::invalid_argument("window options: " + err);
}

bool WindowSource::pull(std::size_t max) {
  if (eof_) return false;
  if (!started_) {
    started_ = true;
    if (std::isfinite(o_.t_start)) reader_.seekTime(o_.t_start);
  }
  while (true) {
    if (!reader_.next(batch_, std::max<std::size_t>(1, max))) {
      eof_ = true;
      return false;
    }
    // The batch up to the first event at or after t_end (time-ordered
    // input: nothing further is in range), without the events before
    // t_start; in one copy where none is before t_start.
    auto last = batch_.begin();
    std::size_t early = 0;
    for (; last != batch_.end() && last->t < o_.t_end; ++last) early += last->t < o_.t_start;
    if (last != batch_.end()) {
      eof_ = true;
      past_end_ = true;
    }
    const std::size_t kept = std::size_t(last - batch_.begin()) - early;
    const bool any = kept > 0;
    if (any) {
      if (buffered() == 0) buf_.clear(), head_ = 0;
      reserveWithHeadroom(buf_, buf_.size() + kept);
      if (early == 0) {
        buf_.insert(buf_.end(), batch_.begin(), last);
      } else {
        for (auto e = batch_.begin(); e != last; ++e)
          if (e->t >= o_.t_start) buf_.push_back(*e);
      }
    }
    peak_ = std::max(peak_, buffered());
    if (any) return true;
    if (eof_) return false;
  }
}

void WindowSource::dropFront(std::size_t n) {
  head_ += std::min(n, buffered());
  if (head_ == buf_.size()) {
    buf_.clear();
    head_ = 0;
  } else if (head_ > buffered()) {
    buf_.erase(buf_.begin(), buf_.begin() + std::ptrdiff_t(head_));
    head_ = 0;
  }
}

void WindowSource::skipGap(double t_next, double S, double step) {
  const double t0 = next_t0_ + double(step_index_) * step;
  if (t_next < t0 + S) return;  // the next event is in this window: no gap
  const double gap = t_next - t0;
  const double empty = std::floor((t_next - t0 - S) / step) + 1.0;  // windows that end before t_next
  if (empty <= double(kMaxEmptyWindows) && gap <= reader_.options().max_time_jump) return;
  // a long gap (or an outlier the reader let through): jump to the window that
  // holds t_next instead of producing every empty window in between
  if (empty < 9.0e15 && double(step_index_) + empty < 9.0e15) {
    step_index_ += std::uint64_t(empty);
  } else {  // too many steps for exact arithmetic: restart the time grid at the event
    next_t0_ = t_next;
    step_index_ = 0;
  }
  ++gaps_;
  skipped_ += empty < 1.8e19 ? std::uint64_t(empty) : std::numeric_limits<std::uint64_t>::max() / 2;
  if (reports_.size() < 20) {
    char msg[240];
    std::snprintf(msg, sizeof msg, "%s: no events in [%.6f, %.6f) s: %.4g empty windows of %g s skipped",
                  reader_.path().c_str(), t0, t_next, empty, S);
    reports_.push_back(msg);
  }
}

bool WindowSource::next(EventWindow& w) {
  w.events.clear();
  w.index = index_;
  if (o_.events_per_window > 0) {
    const std::size_t n = o_.events_per_window;
    if (buf_.capacity() < n) reserveLarge(buf_, n);
    // Reads no further than the window needs: without overlap the buffer
    // then holds exactly the window and is handed over without a copy.
    while (buffered() < n && pull(std::min(o_.read_batch, n - buffered()))) {
    }
    if (buffered() < n) {  // the end: a partial window, or nothing new
      const std::size_t fresh = buffered() - std::min(covered_front_, buffered());
      if (fresh == 0) return false;  // tail_ keeps what became of the last partial window
      tail_ = {fresh, double(buffered()) / double(n), false};
      if (!(o_.keep_partial || tail_.share >= o_.partial_min_share)) return false;
      tail_.emitted = true;
    }
    const std::size_t take = std::min(n, buffered());
    const std::size_t step = std::max<std::size_t>(1, std::size_t(std::floor((1.0 - o_.overlap) * double(n))));
    const std::size_t erased = std::min(step, buffered());
    if (head_ == 0 && take == buf_.size() && erased == take) {
      w.events.swap(buf_);  // the whole buffer is this window and no later one
      buf_.clear();
    } else {
      reserveLarge(w.events, take);
      w.events.assign(begin(), begin() + std::ptrdiff_t(take));
      dropFront(erased);
    }
    w.t0 = w.events.front().t;
    w.t1 = w.events.back().t;
    covered_front_ = take - erased;
    ++index_;
    return true;
  }
  // by duration
  const double S = o_.seconds_per_window;
  const double step = (1.0 - o_.overlap) * S;
  if (index_ == 0 && buffered() == 0) {
    if (!pull(o_.read_batch)) return false;
  }
  if (index_ == 0) next_t0_ = std::isfinite(o_.t_start) ? o_.t_start : begin()->t;
  if (buffered() == 0) pull(o_.read_batch);
  if (buffered() > 0) skipGap(begin()->t, S, step);
  // t0 from the origin and the step count (no accumulated rounding). Without
  // overlap t1 is the next window's t0 computed the same way: t0 + S may
  // round below it, and an event between the two would be in neither window.
  const double t0 = next_t0_ + double(step_index_) * step;
  const double t1 = o_.overlap == 0.0 ? next_t0_ + double(step_index_ + 1) * step : t0 + S;
  if (!(t1 > t0) || !(next_t0_ + double(step_index_ + 1) * step > t0))
    throw IoError(reader_.path() + ": time " + std::to_string(t0) + " s is too large for windows of " +
                  std::to_string(S) + " s (t0 + S == t0 in double precision)");
  // make sure the buffer reaches t1 (or the end); the buffer holds the
  // window's events and at most one batch beyond
  while ((buffered() == 0 || (end() - 1)->t < t1) && pull(o_.read_batch)) {
    if (buffered() > o_.max_events + o_.read_batch) throw tooManyEvents(t0, t1);
  }
  // complete when events reach t1, or the stream passed t_end and t1 <= t_end
  const bool complete = (buffered() > 0 && (end() - 1)->t >= t1) || (past_end_ && t1 <= o_.t_end);
  if (!complete) {  // the end: a partial window, or nothing new
    const auto fresh =
        std::count_if(begin(), end(), [&](const Event& e) { return e.t >= t0 && e.t >= covered_until_; });
    const double span = buffered() == 0 ? 0.0 : std::max(0.0, (end() - 1)->t - t0);
    if (fresh == 0) return false;  // tail_ keeps what became of the last partial window
    tail_ = {std::size_t(fresh), std::min(1.0, span / S), false};
    if (!(o_.keep_partial || tail_.share >= o_.partial_min_share)) return false;
    tail_.emitted = true;
  }
  // The window's events are one run of the time-ordered buffer (times at or
  // above t0, below t1; events before t0 are the previous windows' overlap),
  // copied once into memory of the exact size.
  const Event* first = begin();
  while (first != end() && first->t < t0) ++first;
  const Event* last = first;
  while (last != end() && last->t < t1) ++last;
  // Times going back within the reader's tolerance can leave an event below
  // t0 after the run's start: counted and left out, as one by one.
  std::size_t count = 0;
  for (const Event* e = first; e != last; ++e) count += e->t >= t0;
  if (count > o_.max_events) throw tooManyEvents(t0, t1);
  reserveLarge(w.events, count);
  if (count == std::size_t(last - first)) {
    w.events.assign(first, last);
  } else {
    for (const Event* e = first; e != last; ++e)
      if (e->t >= t0) w.events.push_back(*e);
  }
  w.t0 = t0;
  w.t1 = t1;
  covered_until_ = t1;
  const double following = next_t0_ + double(step_index_ + 1) * step;
  std::size_t drop = 0;
  for (const Event* e = begin(); e != end() && e->t < following; ++e) ++drop;
  dropFront(drop);
  ++step_index_;
  ++index_;
  return true;
}

}  // namespace celc
