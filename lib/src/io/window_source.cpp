#include "celc/io/window_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace celc {

std::string WindowOptions::validate() const {
  if ((events_per_window > 0) == (seconds_per_window > 0.0))
    return "give exactly one of events_per_window (> 0) and seconds_per_window (> 0)";
  if (!std::isfinite(seconds_per_window) || seconds_per_window < 0.0) return "seconds_per_window must be finite, >= 0";
  if (!(overlap >= 0.0 && overlap < 1.0)) return "overlap must be in [0, 1)";
  if (events_per_window > 0 && std::size_t(std::floor((1.0 - overlap) * double(events_per_window))) < 1)
    return "overlap leaves a step of 0 events";
  if (std::isnan(t_start) || std::isnan(t_end) || !(t_end > t_start)) return "need t_start < t_end";
  if (read_batch < 1) return "read_batch must be >= 1";
  return {};
}

WindowSource::WindowSource(EventReader& reader, const WindowOptions& options) : reader_(reader), o_(options) {
  const std::string err = o_.validate();
  if (!err.empty()) throw std::invalid_argument("window options: " + err);
}

bool WindowSource::pull() {
  if (eof_) return false;
  if (!started_) {
    started_ = true;
    if (std::isfinite(o_.t_start)) reader_.seekTime(o_.t_start);
  }
  while (true) {
    if (!reader_.next(batch_, o_.read_batch)) {
      eof_ = true;
      return false;
    }
    bool any = false;
    for (const Event& e : batch_) {
      if (e.t < o_.t_start) continue;
      if (e.t >= o_.t_end) {
        eof_ = true;  // time-ordered input: nothing further is in range
        past_end_ = true;
        break;
      }
      buf_.push_back(e);
      any = true;
    }
    peak_ = std::max(peak_, buf_.size());
    if (any) return true;
    if (eof_) return false;
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
    while (buf_.size() < n && pull()) {
    }
    if (buf_.empty() || (buf_.size() < n && !o_.keep_partial)) return false;
    const std::size_t take = std::min(n, buf_.size());
    w.events.assign(buf_.begin(), buf_.begin() + std::ptrdiff_t(take));
    w.t0 = w.events.front().t;
    w.t1 = w.events.back().t;
    const std::size_t step = std::max<std::size_t>(1, std::size_t(std::floor((1.0 - o_.overlap) * double(n))));
    buf_.erase(buf_.begin(), buf_.begin() + std::ptrdiff_t(std::min(step, buf_.size())));
    ++index_;
    return true;
  }
  // by duration
  const double S = o_.seconds_per_window;
  const double step = (1.0 - o_.overlap) * S;
  if (index_ == 0 && buf_.empty()) {
    if (!pull()) return false;
  }
  if (index_ == 0) next_t0_ = std::isfinite(o_.t_start) ? o_.t_start : buf_.front().t;
  if (buf_.empty()) pull();
  if (!buf_.empty()) skipGap(buf_.front().t, S, step);
  // t0 from the origin and the step count (no accumulated rounding)
  const double t0 = next_t0_ + double(step_index_) * step, t1 = t0 + S;
  if (!(t1 > t0) || !(next_t0_ + double(step_index_ + 1) * step > t0))
    throw IoError(reader_.path() + ": time " + std::to_string(t0) + " s is too large for windows of " +
                  std::to_string(S) + " s (t0 + S == t0 in double precision)");
  // make sure the buffer reaches t1 (or the end)
  while ((buf_.empty() || buf_.back().t < t1) && pull()) {
  }
  // complete when events reach t1, or the stream passed t_end and t1 <= t_end
  const bool complete = (!buf_.empty() && buf_.back().t >= t1) || (past_end_ && t1 <= o_.t_end);
  if (!complete) {
    if (!o_.keep_partial) return false;
    if (std::none_of(buf_.begin(), buf_.end(), [&](const Event& e) { return e.t >= t0; })) return false;
  }
  for (const Event& e : buf_) {
    if (e.t >= t1) break;
    if (e.t >= t0) w.events.push_back(e);
  }
  w.t0 = t0;
  w.t1 = t1;
  const double following = next_t0_ + double(step_index_ + 1) * step;
  while (!buf_.empty() && buf_.front().t < following) buf_.pop_front();
  ++step_index_;
  ++index_;
  return true;
}

}  // namespace celc
