// The schema of the line fitting options (core/fields.hpp).
#include "celc/lines/line_fit.hpp"

namespace celc {

void describe(FieldVisitor& v, LineFitOptions& o) {
  v.enumeration({"model", "", "moving: rotation removed, line linear in time (exact at constant v); static: the paper's still line"},
                o.model, {LineModel::Moving, LineModel::Static});
  v.field({"interval_fraction", "-",
           "each end interval starts as this share of the cluster's duration; 0 = interval_s",
           within(0, 0.5)},
          o.interval_fraction);
  v.field({"interval_s", "s", "end interval length when interval_fraction is 0 (the paper: static, 0.005)", above(0)},
          o.interval_s);
  v.field({"min_events", "events",
           "an interval needs this many (moving: it grows; static: it slides inwards)",
           atLeast(2)},
          o.min_events);
  v.field({"target_length_px", "px",
           "moving: an interval grows until its events span this far along the line",
           atLeast(0)},
          o.target_length_px);
  v.field({"max_rms_px", "px",
           "a fit with a larger residual scale (moving: 1.4826 MAD; static: RMS) is flagged",
           above(0)},
          o.max_rms_px);
  v.field({"min_length_px", "px", "a fit shorter than this along the line is flagged", atLeast(0)}, o.min_length_px);
}

}  // namespace celc
