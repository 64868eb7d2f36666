#pragma once
/// \file line_fit.hpp
/// Boundary lines of one event cluster: l1 near its start, l3 near its end,
/// l2 at its middle, each fitted to the events of an interval there.
///
/// Two line models (LineFitOptions::model):
///  - moving (the default): the line moves inside its interval. Each event's
///    bearing f_j (camera frame at t_j) is turned into the reference frame of
///    the window's motion model with the known rotation, g_j = R(t_j) f_j, and
///    the reference-frame plane normal is fitted as a line in time,
///      n(t) = n0 + (t - t_line) n1,   n(t_j)^T g_j = 0,
///    which is exact for a camera translating at constant velocity (the plane
///    through the centre c(t) and the 3D line (P, d) has normal (P - c(t)) x d).
///    The fit minimises the Huber loss of the point-to-line distances in pixels
///    (iteratively reweighted, scale from the residuals' MAD) with |n0| = 1;
///    the line is n0 turned back into the camera at t_line, where t_line is the
///    mean time of the interval's events (at the interval's edge, a motion of
///    a pixel or two seen through integer pixel positions, a staircase, would
///    tilt the fitted slope and bias the line). Longer intervals add events
///    instead of smear, so an interval grows per cluster until it holds
///    min_events events spanning target_length_px along the line (at most half
///    the cluster's duration; three quarters while it holds too few events).
///  - static: the paper's fit, the line taken as still during a short
///    interval: cv::fitLine with the Huber distance (OpenCV's automatic
///    threshold 1.345 px) over the interval's events, at their mean time; an
///    interval holding too few events slides toward the centre.
/// Fits are done in pixel units (normalised coordinates times the focal length)
/// so that thresholds are in pixels; the result is the unit plane normal of the
/// line in normalised coordinates, camera frame at the line's time.
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc {

enum class LineModel {
  Moving,  ///< n(t) linear in time after removing the rotation (exact at constant velocity)
  Static,  ///< the paper's still line over a short interval
};
std::string toString(LineModel model);  ///< "moving" | "static"

struct LineFitOptions {
  LineModel model = LineModel::Moving;
  /// Each end interval starts as this share of the cluster's duration (moving
  /// model; it then grows as needed, up to 0.5). 0 = use interval_s.
  double interval_fraction = 0.1;
  /// Length of each end interval [s] when interval_fraction is 0 (static
  /// model: always; the paper's 5 ms).
  double interval_s = 0.005;
  int min_events = 8;               ///< events an interval needs (moving: grows; static: slides)
  /// Moving model: an interval grows until its events span this far along the line [px].
  double target_length_px = 20.0;
  /// A fit whose residual scale (moving: 1.4826 MAD; static: RMS) is larger [px] is flagged.
  double max_rms_px = 3.0;
  /// A fit whose points extend less than this along the line [px] is flagged
  /// (its direction is ill-defined).
  double min_length_px = 3.0;
  std::string validate() const;     ///< empty when valid
};
/// The schema of the `lines:` section (core/fields.hpp).
void describe(FieldVisitor& v, LineFitOptions& options);


/// Ok; TooFewEvents (the interval, grown or slid as far as allowed, still held
/// fewer than min_events); PoorFit (residual scale above max_rms_px or length
/// below min_length_px: see FittedLine::rms_ok / length_ok).
enum class LineFitStatus { Ok, TooFewEvents, PoorFit };
std::string toString(LineFitStatus status);

struct FittedLine {
  TimedLine line;            ///< plane normal (unit), camera frame at line.t [s]
  double t_begin = 0.0;      ///< interval actually used [s] (after growing / sliding), half-open [t_begin, t_end)
  double t_end = 0.0;
  double t_first = 0.0;      ///< time of the first event used [s]
  double t_last = 0.0;       ///< time of the last event used [s]
  bool slid = false;         ///< static: the interval was moved toward the centre; moving: it was grown
  int n_events = 0;
  double rms_px = 0.0;       ///< residual scale [px] (moving: 1.4826 MAD of the distances; static: RMS)
  double length_px = 0.0;    ///< extent of the points along the line [px]
  bool rms_ok = false;       ///< rms_px <= max_rms_px
  bool length_ok = false;    ///< length_px >= min_length_px
  LineFitStatus status = LineFitStatus::TooFewEvents;
};

struct ClusterLines {
  FittedLine l1, l2, l3;
  bool ok() const {
    return l1.status == LineFitStatus::Ok && l3.status == LineFitStatus::Ok && l3.line.t > l1.line.t;
  }
};

/// Static line through bearings (x, y, 1) [normalised]; focal_px scales to
/// pixels; the line's time is the mean of `times`.
FittedLine fitLine(const std::vector<Vec3>& bearings, const std::vector<double>& times,
                   double focal_px);

/// Fits l1, l2 and l3 of a cluster. `times` must be sorted ascending (otherwise,
/// or with focal_px <= 0, every line is returned with status TooFewEvents).
/// `motion` gives the rotation R(t) (its translation is not used); without it
/// the camera is taken as not rotating.
ClusterLines fitClusterLines(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             double focal_px, const LineFitOptions& options,
                             const MotionModel* motion = nullptr);

/// Fits the lines of a cluster and stores them in it (l1, l2, l3, has_l2,
/// has_lines). Returns false (has_lines false) when l1 or l3 could not be fitted.
bool attachFittedLines(ClusterObservation& cluster, double focal_px, const LineFitOptions& options,
                       const MotionModel* motion = nullptr);

}  // namespace celc
