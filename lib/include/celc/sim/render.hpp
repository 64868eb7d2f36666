#pragma once
/// \file render.hpp
/// The rendering event simulator (after ESIM, Rebecq et al. 2018, and v2e,
/// Hu et al. 2021): the scene is rendered at adaptive time steps and every
/// pixel turns its log-intensity change into events.
///
/// Per pixel i (centre (x, y), bearing from CameraModel::bearing):
///  - L = log(eps + I), I the anti-aliased intensity in [0, 1];
///  - thresholds C+_i = C+ + sigma N(0,1), C-_i = C- + sigma N(0,1) drawn once
///    (fixed mismatch, clamped to >= 0.01);
///  - a reference level L_ref (the level of the last crossing); between two
///    renders (t_k, L_k) -> (t_k+1, L_k+1) L is linear in t, and every crossing
///    of L_ref + C+_i (ON) or L_ref - C-_i (OFF) gives an event at its
///    interpolated time; L_ref moves by one threshold per crossing, so that
///    L_ref - C-_i < L < L_ref + C+_i holds after every render;
///  - timestamps are rounded to 1 us; an event less than `refractory` after
///    the pixel's previous emitted event (rounded times) is dropped (its
///    crossing still moves L_ref, as v2e's refractory filter);
///  - background noise: a Poisson process of `noise_rate` [Hz] per pixel with
///    random polarity; noise events obey the refractory period but do not move
///    L_ref; their label is -1.
/// Render steps: dt = min(max_step, max_step_px / max image speed), the speed
/// measured on a grid of pixels by projecting their scene points at t and
/// t + 0.1 ms, so that edges move at most ~max_step_px pixels per step.
/// Pixels far from every edge are not re-shaded until an edge could reach them.
/// Threads split the image into row bands; the result does not depend on the
/// thread count (per-pixel random streams, merge by (t, y, x)).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/geometry/camera.hpp"
#include "celc/sim/scene.hpp"
#include "celc/sim/scene_trajectory.hpp"

namespace celc {

struct RenderOptions {
  double contrast_on = 0.25;     ///< C+ [log intensity]
  double contrast_off = 0.25;    ///< C- [log intensity]
  double contrast_sigma = 0.03;  ///< per-pixel threshold mismatch, std [log intensity]
  double refractory = 5e-4;      ///< [s]; 0 disables
  double noise_rate = 0.0;       ///< background events per pixel [Hz], <= 1000
  double log_eps = 1e-2;         ///< eps in L = log(eps + I), I in [0, 1]
  double max_step_px = 0.3;      ///< largest image motion per render step [px]
  double max_step = 2e-3;        ///< largest render step [s]
  double min_step = 1e-6;        ///< smallest render step [s]
  double smoothing_px = 1.0;     ///< width of the anti-aliasing ramp across edges [px]
  /// Skip shading a pixel until an edge could reach it: the larger of the
  /// time its nearest edges need at the texture's own velocity at the pixel
  /// (per chessboard line family, 1.5x margin) and at 1.5x the image's
  /// largest speed; at most 50 ms, up to the next jump of a piecewise twist,
  /// 0.01 / f for a sinusoid. false shades every pixel at every step.
  bool skip_static = true;
  int threads = 2;               ///< worker threads (1..64)
  uint64_t seed = 1;             ///< thresholds and noise
  std::string validate() const;  ///< empty when valid
};
/// The schema of a scene's `events:` section (core/fields.hpp).
void describe(FieldVisitor& v, RenderOptions& options);

/// One simulated event: time [us], pixel, polarity and the scene edge that
/// triggered it (-1: background noise).
struct SimEvent {
  int64_t t_us = 0;
  uint16_t x = 0, y = 0;
  bool on = true;
  int32_t label = -1;
};

/// The library's event type (time in seconds).
inline Event toEvent(const SimEvent& e) {
  Event out;
  out.t = static_cast<double>(e.t_us) * 1e-6;
  out.x = static_cast<float>(e.x);
  out.y = static_cast<float>(e.y);
  out.on = e.on;
  return out;
}

struct RenderStats {
  int64_t renders = 0;        ///< images rendered (including the first)
  int64_t pixels_shaded = 0;  ///< pixel evaluations after the first image
  int64_t events_on = 0;
  int64_t events_off = 0;
  int64_t events_noise = 0;  ///< included in on/off
  int64_t refractory_dropped = 0;
  double min_step = 0.0, max_step = 0.0;  ///< render steps used [s]
};

class RenderEventSimulator {
 public:
  /// Renders the first image at t0. Throws std::invalid_argument when the
  /// options or the camera are invalid (the CLI reports it).
  RenderEventSimulator(const Scene& scene, const CameraModel& camera, const Trajectory& trajectory,
                       const RenderOptions& options, double t0 = 0.0);
  ~RenderEventSimulator();
  RenderEventSimulator(const RenderEventSimulator&) = delete;
  RenderEventSimulator& operator=(const RenderEventSimulator&) = delete;

  /// Simulates (time(), t_end] and appends its events, sorted by (t, y, x), to `out`.
  /// The last render is exactly at t_end.
  void advanceTo(double t_end, std::vector<SimEvent>& out);

  double time() const;
  const RenderStats& stats() const;
  /// Per-pixel state after the last render (index y * width + x).
  const std::vector<float>& logIntensity() const;  ///< L at time()
  const std::vector<float>& reference() const;     ///< L_ref
  const std::vector<float>& thresholdOn() const;   ///< C+_i
  const std::vector<float>& thresholdOff() const;  ///< C-_i
  /// Image speed [px/s] that sets the step at time t (max over the sample grid).
  double imageSpeed(double t) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Renders the log-intensity image L = log(eps + I) at time t (row-major).
std::vector<float> renderLogImage(const Scene& scene, const CameraModel& camera,
                                  const RigidPose& T_world_cam, double log_eps,
                                  double smoothing_px);

/// Pixel bearings (x, y, 1) of the pixel centres, undistorted, row-major
/// (two numbers per pixel).
std::vector<double> pixelBearings(const CameraModel& camera);

}  // namespace celc
