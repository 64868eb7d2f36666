#pragma once
/// \file line_fit.hpp
/// Boundary lines of one event cluster: l1 from its first events, l3 from its
/// last, l2 from those around its middle, each fitted with cv::fitLine and the
/// Huber distance. Points are fitted in pixel units (normalised coordinates
/// times the focal length) so that the Huber threshold (1.345, OpenCV's
/// automatic choice) is in pixels; the result is the unit plane normal of the
/// line in normalised coordinates. A line's time is the mean time of the
/// events it was fitted to (the line moves during the interval).
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/observations.hpp"

namespace celc {

struct LineFitOptions {
  double interval_s = 0.005;        ///< length of each end interval [s]
  /// When > 0, the interval is this fraction of the cluster's duration instead
  /// of interval_s (for sparse events, e.g. 0.1 = first and last 10%).
  double interval_fraction = 0.0;
  int min_events = 8;               ///< events an interval needs; it slides toward the centre otherwise
  double max_rms_px = 3.0;          ///< a fit with a larger RMS point-line distance [px] is flagged
  /// A fit whose points extend less than this along the line [px] is flagged
  /// (its direction is ill-defined).
  double min_length_px = 3.0;
  std::string validate() const;     ///< empty when valid
};
/// The schema of the `lines:` section (core/fields.hpp).
void describe(FieldVisitor& v, LineFitOptions& options);


/// Ok; TooFewEvents (the interval, slid to the centre, still held fewer than
/// min_events); PoorFit (RMS residual above max_rms_px or length below
/// min_length_px: see FittedLine::rms_ok / length_ok).
enum class LineFitStatus { Ok, TooFewEvents, PoorFit };
std::string toString(LineFitStatus status);

struct FittedLine {
  TimedLine line;            ///< plane normal (unit) and time [s] (mean time of the events used)
  double t_begin = 0.0;      ///< interval actually used [s] (after sliding), half-open [t_begin, t_end)
  double t_end = 0.0;
  double t_first = 0.0;      ///< time of the first event used [s]
  double t_last = 0.0;       ///< time of the last event used [s]
  bool slid = false;         ///< the interval was moved toward the centre (too few events at the end)
  int n_events = 0;
  double rms_px = 0.0;       ///< RMS point-to-line distance [px]
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

/// Fits a line to bearings (x, y, 1) [normalised]; focal_px scales to pixels.
FittedLine fitLine(const std::vector<Vec3>& bearings, const std::vector<double>& times,
                   double focal_px);

/// Fits l1, l2 and l3 of a cluster. `times` must be sorted ascending (otherwise,
/// or with focal_px <= 0, every line is returned with status TooFewEvents).
ClusterLines fitClusterLines(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             double focal_px, const LineFitOptions& options);

/// Fits the lines of a cluster and stores them in it (l1, l2, l3, has_l2).
/// Returns false when l1 or l3 could not be fitted.
bool attachFittedLines(ClusterObservation& cluster, double focal_px, const LineFitOptions& options);

}  // namespace celc
