#pragma once
/// \file observations.hpp
/// What the solvers see of a window: per line cluster its events as
/// undistorted bearings and its boundary lines. No pixels, no files.
///
/// An image line is stored as the normal l of the plane through the camera
/// centre and the line (l^T (x, y, 1) = 0 for points on it), unit norm, in the
/// camera frame at the line's own time.
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

/// An image line at time t: plane normal in the camera frame at t (unit).
struct TimedLine {
  Vec3 normal = Vec3::UnitX();
  double t = 0.0;  ///< [s]
};

/// One space-time cluster of events triggered by one straight 3D edge.
struct ClusterObservation {
  std::vector<double> times;    ///< event times [s]
  std::vector<Vec3> bearings;   ///< undistorted (x, y, 1) per event, camera frame at the event time
  TimedLine l1;                 ///< line at the cluster's start t_s
  TimedLine l3;                 ///< line at the cluster's end t_e
  TimedLine l2;                 ///< middle line at t_m (CE3LC)
  bool has_l2 = false;
  /// l1 and l3 were fitted. False: the events alone (a line fit failed):
  /// npt, which needs no fitted lines, uses them; the line methods skip them.
  bool has_lines = true;
  int id = -1;                  ///< caller's label (cluster id)
  size_t size() const { return times.size(); }
};

/// The accelerometer's view of a window: the camera's mean acceleration
/// over [t0, t1] in the reference frame (the camera at the motion model's
/// t_ref), gravity removed, with its 1-sigma error per axis. Not valid
/// without an accelerometer or without gravity (pipeline/accelerometer.hpp).
struct MeasuredAcceleration {
  bool valid = false;
  Vec3 a = Vec3::Zero();  ///< [m/s^2], reference frame
  double sigma = 0.0;     ///< [m/s^2] per axis
  double t0 = 0.0, t1 = 0.0;  ///< [s] the first and last sample averaged
};

/// All clusters of one window.
struct WindowObservations {
  std::vector<ClusterObservation> clusters;
  double focal_px = 320.0;  ///< converts normalised distances to pixels (thresholds are in px)
  MeasuredAcceleration accelerometer;  ///< celc_acc's check (solver/options.hpp AccOptions)
};

}  // namespace celc
