#include "celc/pipeline/window_policy.hpp"
#include "celc/core/memory.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "celc/geometry/line_motion.hpp"

namespace celc {

std::string toString(WindowPolicy policy) {
  switch (policy) {
    case WindowPolicy::Parallax: return "parallax";
    case WindowPolicy::Events: return "events";
    case WindowPolicy::Seconds: return "seconds";
  }
  return "?";
}

std::string ParallaxWindowOptions::validate() const {
  std::ostringstream e;
  e.precision(6);
  e << rangeProblemsOf(*this);
  // The rules that tie fields together.
  if (!(no_parallax_px >= 0.0) || !(no_parallax_px <= target_px))
    e << "no_parallax_px: must be in [0, parallax_px (" << target_px << ")], got " << no_parallax_px << "; ";
  if (std::isfinite(max_seconds) && !(max_seconds >= min_seconds))
    e << "max_seconds: must be >= min_seconds (" << min_seconds << "), got " << max_seconds << "; ";
  else if (std::isfinite(max_seconds) && step_seconds > 0.0 && max_seconds / step_seconds > 10000.0)
    e << "max_seconds: more than 10000 steps of step_seconds; ";
  if (std::isfinite(slow_turn_max_seconds) && step_seconds > 0.0 && slow_turn_max_seconds / step_seconds > 10000.0)
    e << "slow_turn_max_seconds: more than 10000 steps of step_seconds; ";
  return e.str();
}

void describe(FieldVisitor& v, ParallaxWindowOptions& o) {
  v.field({"parallax_px", "px", "parallax policy: grow a window until its lines' translation reaches this", above(0)},
          o.target_px);
  v.field({"no_parallax_px", "px",
           "parallax policy: a window grown to its longest (max_seconds, or slow_turn_max_seconds) with less is "
           "degenerate (no_parallax)"},
          o.no_parallax_px);
  v.field({"min_seconds", "s", "parallax policy: shortest window", above(0)}, o.min_seconds);
  v.field({"max_seconds", "s",
           "parallax policy: longest window but where the camera turns slowly (reached without parallax: "
           "degenerate)", anyFinite()},
          o.max_seconds);
  v.field({"slow_turn_max_seconds", "s",
           "parallax policy: longest window while the camera turns less than slow_turn_rad over it (at or "
           "below max_seconds: none grows past max_seconds)", above(0)},
          o.slow_turn_max_seconds);
  v.field({"slow_turn_rad", "rad",
           "parallax policy: a window turning less than this (|mean gyro rate| x duration) may grow past "
           "max_seconds", atLeast(0)},
          o.slow_turn_rad);
  v.field({"step_seconds", "s", "parallax policy: windows grow by whole steps of this", above(0)}, o.step_seconds);
  v.field({"probe_events", "events",
           "parallax policy: events clustered to measure a growing window, per max_seconds of window", atLeast(1000)},
          o.probe_events);
}

std::size_t ParallaxWindowOptions::probeBudget(double seconds) const {
  const double scale = std::max(1.0, seconds / max_seconds);
  return static_cast<std::size_t>(std::ceil(static_cast<double>(probe_events) * scale));
}

double lineTranslationPx(const WindowObservations& obs, const MotionModel& motion, double t0, double t1,
                         int min_clusters) {
  std::vector<double> d;
  for (const ClusterObservation& c : obs.clusters) {
    const double span = c.l3.t - c.l1.t;
    if (!c.has_lines || c.size() == 0 || !(span >= kMinSpanShare * (t1 - t0))) continue;
    const double px = lineMotionPx(c, motion, obs.focal_px) * (t1 - t0) / span;
    if (std::isfinite(px)) d.push_back(px);
  }
  if (static_cast<int>(d.size()) < std::max(1, min_clusters)) return NAN;
  const auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

int nextWindowSteps(int steps, double d_px, double target_px, int max_steps) {
  double factor = 3.0;
  if (std::isfinite(d_px) && d_px > 0.0) factor = std::clamp(target_px / d_px, 1.5, 3.0);
  const int next = static_cast<int>(std::ceil(steps * factor - 1e-9));
  return std::min(max_steps, std::max(steps + 1, next));
}

ParallaxWindowJoiner::ParallaxWindowJoiner(WindowSource& steps, const ParallaxWindowOptions& options,
                                           double partial_min_share, Probe probe, Turn turn)
    : source_(steps),
      o_(options),
      partial_min_share_(partial_min_share),
      probe_(std::move(probe)),
      turn_(std::move(turn)) {}

int ParallaxWindowJoiner::maxStepsFrom(double t0, int max_steps) const {
  const int slow_steps = static_cast<int>(std::floor(o_.slow_turn_max_seconds / o_.step_seconds + 1e-9));
  int steps = max_steps;
  if (!turn_) return steps;
  while (steps < slow_steps && turn_(t0, t0 + (steps + 1) * o_.step_seconds) <= o_.slow_turn_rad) ++steps;
  return steps;
}

int ParallaxWindowJoiner::contiguousSteps(int wanted) {
  const double tolerance = 1e-6 * o_.step_seconds;
  auto contiguous = [&] {
    int n = pending_.empty() ? 0 : 1;
    while (n < static_cast<int>(pending_.size()) &&
           std::abs(pending_[static_cast<std::size_t>(n)].t0 - pending_[static_cast<std::size_t>(n - 1)].t1) <=
               tolerance)
      ++n;
    return n;
  };
  int n = contiguous();
  while (n < wanted && n == static_cast<int>(pending_.size()) && !source_done_) {
    EventWindow step;
    if (!source_.next(step)) {
      source_done_ = true;
      break;
    }
    pending_.push_back(std::move(step));
    n = contiguous();
  }
  return n;
}

int ParallaxWindowJoiner::tailToJoin(int steps, int longest) {
  if (!(translation_px_ >= o_.target_px) || steps >= longest) return 0;
  // With D linear in the length, the rest shows target_px only from `need`
  // steps on; look that far ahead, or one step past the longest window.
  const int need = static_cast<int>(std::ceil(steps * o_.target_px / translation_px_ - 1e-9));
  const int look = std::min(std::max(1, need), longest - steps + 1);
  const int have = contiguousSteps(steps + look);
  return have < steps + look ? have - steps : 0;  // the run of data ends within it
}

void ParallaxWindowJoiner::join(int steps) {
  if (steps < joined_steps_) {
    std::size_t n = 0;
    for (int i = 0; i < steps; ++i) n += pending_[static_cast<std::size_t>(i)].events.size();
    joined_.resize(n);
    joined_steps_ = steps;
    return;
  }
  std::size_t n = joined_.size();
  for (int i = joined_steps_; i < steps; ++i) n += pending_[static_cast<std::size_t>(i)].events.size();
  if (n > source_.options().max_events)
    throw source_.tooManyEvents(pending_.front().t0, pending_[static_cast<std::size_t>(steps - 1)].t1);
  reserveLarge(joined_, n);
  for (int i = joined_steps_; i < steps; ++i) {
    const auto& e = pending_[static_cast<std::size_t>(i)].events;
    joined_.insert(joined_.end(), e.begin(), e.end());
  }
  joined_steps_ = steps;
}

bool ParallaxWindowJoiner::next(EventWindow& window) {
  const int min_steps = std::max(1, static_cast<int>(std::ceil(o_.min_seconds / o_.step_seconds - 1e-9)));
  const int max_steps = std::max(min_steps, static_cast<int>(std::floor(o_.max_seconds / o_.step_seconds + 1e-9)));
  // The first try is the last window's length (the motion changes slowly);
  // one that shows twice the target is shrunk once toward it.
  // Where the camera turns slowly the window may grow past max_seconds.
  const int have_first = contiguousSteps(1);
  if (have_first == 0) return false;
  const int longest = maxStepsFrom(pending_.front().t0, max_steps);
  int steps = std::clamp(last_steps_, min_steps, longest);
  bool may_shrink = steps > min_steps;
  bool measured = false;  // a finite D on a shorter try of this window
  // D of each length tried: a shrink followed by a grow can come back to a
  // length already measured (the probe is seeded, so D would be the same).
  std::vector<std::pair<int, double>> tried;
  translation_px_ = NAN;
  for (;;) {
    const int have = contiguousSteps(steps);
    if (have == 0) return false;
    if (have < steps) {  // the data or a gap ends the window: not measured
      steps = have;
      translation_px_ = NAN;
      break;
    }
    const auto seen = std::find_if(tried.begin(), tried.end(), [&](const auto& x) { return x.first == steps; });
    if (seen != tried.end()) {
      translation_px_ = seen->second;
    } else {
      join(steps);
      translation_px_ = probe_(pending_.front().t0, pending_[static_cast<std::size_t>(steps - 1)].t1, joined_);
      tried.emplace_back(steps, translation_px_);
    }
    if (may_shrink && translation_px_ >= 2.0 * o_.target_px) {
      may_shrink = false;
      steps = std::max(min_steps, static_cast<int>(std::ceil(steps * o_.target_px / translation_px_ - 1e-9)));
      continue;
    }
    if (!std::isfinite(translation_px_)) {
      // No cluster of the probe spans enough of this longer window (fast
      // motion ends clusters early, or the probe's subsample is too sparse
      // for the clustering): a longer window would not measure better. After
      // a finite D, keep the length aimed at from it; a warm start that
      // cannot be measured starts again from the shortest window.
      if (measured) break;
      if (may_shrink) {
        may_shrink = false;
        steps = min_steps;
        continue;
      }
    }
    may_shrink = false;
    measured = measured || std::isfinite(translation_px_);
    if (translation_px_ >= o_.target_px || steps >= longest) break;
    steps = nextWindowSteps(steps, translation_px_, o_.target_px, longest);
  }
  last_steps_ = std::isfinite(translation_px_) || measured ? steps : min_steps;
  steps += tailToJoin(steps, longest);
  join(steps);
  window.events.clear();
  window.events.swap(joined_);  // handed over without a copy
  joined_steps_ = 0;
  window.t0 = pending_.front().t0;
  window.t1 = pending_[static_cast<std::size_t>(steps - 1)].t1;
  const bool at_end = source_done_ && static_cast<int>(pending_.size()) == steps;
  if (at_end && steps < min_steps) {  // the end of the data cut the window short
    std::size_t events = window.events.size();
    const double span = events == 0 ? 0.0 : window.events.back().t - window.t0;
    tail_ = {events, std::min(1.0, span / o_.min_seconds), false};
    if (events == 0 || tail_.share < partial_min_share_) {
      pending_.clear();
      return false;
    }
    tail_.emitted = true;
  }
  pending_.erase(pending_.begin(), pending_.begin() + steps);
  window.index = index_++;
  return true;
}

}  // namespace celc
