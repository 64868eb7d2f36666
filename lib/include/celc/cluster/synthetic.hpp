#pragma once
/// \file synthetic.hpp
/// Labelled synthetic windows for testing and benchmarking the clustering:
/// straight 3D segments in front of a pinhole camera moving with a constant
/// twist (v, w) (celc::MotionModel::constantTwist, t_ref = 0), events drawn
/// uniformly over each segment's swept surface in space-time, projected,
/// perturbed by Gaussian pixel noise and rounded to the pixel grid, plus
/// uniform noise events. Every event carries its true line label (-1 = noise).
/// Deterministic for a given seed.
#include <vector>

#include "celc/geometry/camera.hpp"
#include "celc/core/types.hpp"

namespace celc {

struct LabelledWindowOptions {
  CameraModel camera = [] {
    CameraModel c;
    c.width = 240, c.height = 180, c.fx = c.fy = 200.0, c.cx = 120.0, c.cy = 90.0;
    return c;
  }();                            ///< default: DAVIS240C-like, no distortion
  int n_lines = 8;
  int n_events = 30000;           ///< total, noise included
  double noise_fraction = 0.1;    ///< share of uniform noise events
  double duration_s = 0.1;        ///< window [0, duration_s)
  double pixel_noise_px = 0.7;    ///< Gaussian sigma before rounding [px]
  double speed_m_per_s = 1.0;     ///< |v|, random direction
  double omega_rad_per_s = 0.3;   ///< |w|, random axis
  double depth_min_m = 1.5, depth_max_m = 4.0;
  double min_length_px = 40.0, max_length_px = 120.0;  ///< segment length at t = 0 [px]
  /// Candidate segments closer than this (midpoints at t=0 and t=T) to an accepted one are redrawn [px].
  double min_separation_px = 12.0;
  unsigned seed = 1;
};

struct LabelledWindow {
  std::vector<Event> events;  ///< sorted by time
  std::vector<int> labels;    ///< true line per event, -1 = noise
  CameraModel camera;
  Vec3 v = Vec3::Zero();      ///< body-frame linear velocity [m/s]
  Vec3 omega = Vec3::Zero();  ///< [rad/s]
  std::vector<Vec3> p1, p2;   ///< segment end points in the camera frame at t = 0 [m]
  int n_lines() const { return static_cast<int>(p1.size()); }
  /// Unit normal of the plane through the camera centre and line `line` at time t,
  /// in the camera frame at t (the true image line, l^T (x, y, 1) = 0).
  Vec3 lineNormal(int line, double t) const;
};

LabelledWindow generateLabelledWindow(const LabelledWindowOptions& options);

}  // namespace celc
