#pragma once
/// \file window_policy.hpp
/// How `celc run` chooses the length of its windows (`windows.policy`):
///  - events: a fixed count of events (the paper's 30,000);
///  - seconds: a fixed duration;
///  - parallax (the default): each window grows in time until its boundary
///    lines show enough translation, or a maximum duration is reached.
/// The translation a window shows is measured on its clusters' lines: with
/// the rotation removed (the motion model's R(t), from the gyroscope), l1 and
/// l3 of a cluster differ only by what translation moved; how far, in pixels,
/// is read at the cluster's centroid c (its events turned into the reference
/// frame), where a line's position is well defined even when its direction
/// is not: with m1 = R(t1) l1, m3 = R(t3) l3 and d(m) = m . c / |m_xy|,
///   D = median over clusters of f |d(m1) - d(m3)| (t_end - t_start) / (t3 - t1)   [px],
/// over the clusters with lines whose t3 - t1 covers at least a quarter of
/// the window (a short one, scaled up to the window, would mostly add noise).
/// The accuracy of the line methods follows D (docs/running.md): a window is
/// grown until D >= parallax_px.
#include <cmath>
#include <cstddef>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/io/window_source.hpp"

namespace celc {

enum class WindowPolicy { Parallax, Events, Seconds };
std::string toString(WindowPolicy policy);  ///< "parallax" | "events" | "seconds"

/// The parallax policy's options (keys of the `windows:` section).
struct ParallaxWindowOptions {
  double target_px = 25.0;     ///< grow until the lines' translation D reaches this [px]
  /// A window grown to its longest (max_seconds, or slow_turn_max_seconds
  /// where the camera turns slowly) with D below this [px] is degenerate
  /// (no_parallax) for every method; between it and target_px it is solved,
  /// and sigma_deg (8-12 deg at 3-5 px) says how little it shows.
  double no_parallax_px = 3.0;
  double min_seconds = 0.05;   ///< first (shortest) window tried [s]
  double max_seconds = 0.3;    ///< longest window [s]; see no_parallax_px and the next two
  /// A window that turns slowly may grow past max_seconds, up to this [s]:
  /// while the camera's rotation over it, |mean gyro rate| x duration, stays
  /// within slow_turn_rad. Under fast rotation lines sweep across the image
  /// and long windows hold fragments; a slowly turning camera far from the
  /// scene needs them (1 m/s at 3-6 m shows ~20 px of translation per second).
  /// At or below max_seconds no window grows past max_seconds.
  double slow_turn_max_seconds = 1.0;
  double slow_turn_rad = 0.5;  ///< see slow_turn_max_seconds [rad]
  /// Growth is in steps of this duration [s]: windows are whole numbers of steps.
  double step_seconds = 0.025;
  /// The measurement of D while a window grows clusters at most this many
  /// events per max_seconds of window (every k-th event of the window;
  /// denser where that finds no D); the window itself keeps all. A sparser
  /// probe measures less D: a 1 s window probed on 30,000 events showed
  /// a third of its D, hence a budget growing with the window's length.
  std::size_t probe_events = 30000;
  /// The probe's budget for a window of `seconds` [events].
  std::size_t probeBudget(double seconds) const;
  std::string validate() const;  ///< "key: what; " per problem ("" = valid)
};
/// The parallax keys of the `windows:` section (core/fields.hpp).
void describe(FieldVisitor& v, ParallaxWindowOptions& options);

/// Clusters count for D when t3 - t1 is at least this share of the window.
constexpr double kMinSpanShare = 0.25;
/// D of the window [t0, t1] (see the file comment) [px]; NaN when fewer than
/// `min_clusters` clusters count.
double lineTranslationPx(const WindowObservations& obs, const MotionModel& motion, double t0, double t1,
                         int min_clusters = 3);

/// The next length to try [steps] after a window of `steps` steps showed D px:
/// at least 1.5x and at most 3x longer, aiming at target_px with D linear in
/// the length; `max_steps` caps it.
int nextWindowSteps(int steps, double d_px, double target_px, int max_steps);

/// The parallax policy's windows, joined from consecutive steps of a
/// WindowSource cut by duration (step_seconds each, no overlap). A window
/// starts as long as the last one (min_seconds at first, and after a window
/// the probe could not measure); one that shows twice target_px is shrunk
/// once toward it; while the probe measures D < target_px it grows by
/// nextWindowSteps, up to max_seconds (where D is measured once more), or
/// up to slow_turn_max_seconds where the camera turns slowly. A gap the
/// source skipped ends a window.
/// A window that shows target_px is joined with the rest of the data (to its
/// end or a gap) when that rest is too short to show target_px itself (D
/// linear in the length) and the longest window allows.
/// The last window, cut by the end of the data, is emitted when its events
/// span at least partial_min_share of min_seconds (else tail() reports it).
/// Memory: at most max(max_seconds, slow_turn_max_seconds) of events, and one step.
class ParallaxWindowJoiner {
 public:
  /// D [px] of the window [t0, t1) holding `events` (NaN: not measurable).
  using Probe = std::function<double(double t0, double t1, const std::vector<Event>& events)>;
  /// How far the camera turns over [t0, t1] [rad] (NaN: unknown).
  using Turn = std::function<double(double t0, double t1)>;
  /// Without `turn`, no window grows past max_seconds.
  ParallaxWindowJoiner(WindowSource& steps, const ParallaxWindowOptions& options, double partial_min_share,
                       Probe probe, Turn turn = nullptr);
  /// The next window (indices 0, 1, ...); false when none remains.
  bool next(EventWindow& window);
  /// After next() returned false: the last, partial window, emitted or not.
  const WindowTail& tail() const { return tail_; }
  /// D [px] measured on the window next() returned last: >= target_px, or
  /// less when it stopped at max_seconds; NaN when not measured (cut short by
  /// the data or a gap) or not measurable. With a rest of the data joined,
  /// D of the window before it.
  double translationPx() const { return translation_px_; }

 private:
  /// Pulls steps until `wanted` contiguous ones are pending; returns how many are.
  int contiguousSteps(int wanted);
  /// The longest window [steps] starting at t0: max_seconds, or longer up to
  /// slow_turn_max_seconds while the camera turns less than slow_turn_rad.
  int maxStepsFrom(double t0, int max_steps) const;
  /// Steps to add to a window of `steps` that showed D >= target_px: the rest
  /// of the data (to its end or to a gap), when that rest is too short to
  /// show target_px itself (D linear in the length) and the joined window
  /// stays within `longest` steps; else 0.
  int tailToJoin(int steps, int longest);
  /// joined_ becomes the first `steps` pending steps' events: a longer try
  /// appends the steps it adds, a shorter one cuts the vector (each event is
  /// copied once per window, however many lengths the probes try).
  void join(int steps);
  WindowSource& source_;
  ParallaxWindowOptions o_;
  double partial_min_share_;
  Probe probe_;
  Turn turn_;
  std::deque<EventWindow> pending_;
  std::vector<Event> joined_;  ///< the events of pending_'s first joined_steps_ steps
  int joined_steps_ = 0;
  bool source_done_ = false;
  std::uint64_t index_ = 0;
  WindowTail tail_;
  double translation_px_ = NAN;
  int last_steps_ = 0;  ///< steps of the last measured window (0: none yet)
};

}  // namespace celc
