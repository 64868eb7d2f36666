// The schema of the line fitting options (core/fields.hpp).
#include "celc/lines/line_fit.hpp"

namespace celc {

void describe(FieldVisitor& v, LineFitOptions& o) {
  v.field({"interval_s", "s", "length of each end interval (l1 at the start, l3 at the end)"}, o.interval_s);
  v.field({"interval_fraction", "-", "> 0: the interval is this share of the cluster's duration"},
          o.interval_fraction);
  v.field({"min_events", "events", "an interval needs this many; it slides inwards otherwise"}, o.min_events);
  v.field({"max_rms_px", "px", "a fit with a larger RMS point-line distance is flagged"}, o.max_rms_px);
  v.field({"min_length_px", "px", "a fit shorter than this along the line is flagged"}, o.min_length_px);
}

}  // namespace celc
