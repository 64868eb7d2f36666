// The schema of the evaluation options (core/fields.hpp).
#include "celc/eval/gt_velocity.hpp"

namespace celc {

void describe(FieldVisitor& v, GtVelocityOptions& o) {
  v.field({"half_width", "s", "local polynomial fit of the poses over +-half_width", above(0)}, o.half_width);
  v.field({"degree", "", "polynomial degree (1..4)", within(1, 4)}, o.degree);
  v.field({"min_poses", "", "poses needed inside the neighbourhood"}, o.min_poses);
  v.field({"samples", "", "evaluation times per window", atLeast(1)}, o.samples);
}

}  // namespace celc
