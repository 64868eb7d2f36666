// The schema of the geometry module's options (core/fields.hpp).
#include "celc/geometry/camera.hpp"

namespace celc {

void describe(FieldVisitor& v, CameraModel& c) {
  v.field({"width", "px", "sensor width", atLeast(1)}, c.width);
  v.field({"height", "px", "sensor height", atLeast(1)}, c.height);
  v.field({"fx", "px", "focal length along x", above(0)}, c.fx);
  v.field({"fy", "px", "focal length along y", above(0)}, c.fy);
  v.field({"cx", "px", "principal point x", anyFinite()}, c.cx);
  v.field({"cy", "px", "principal point y", anyFinite()}, c.cy);
  v.enumeration({"distortion_model", "", "lens distortion"}, c.distortion,
                {DistortionModel::None, DistortionModel::RadTan, DistortionModel::Equidistant});
  v.member(&c.coeffs, sizeof c.coeffs);
  std::vector<double> d(c.coeffs.begin(), c.coeffs.end());
  v.field({"distortion", "-", "radtan: k1 k2 p1 p2 [k3]; equidistant: k1 k2 k3 k4", anyFinite()}, d, {0, 4, 5});
  c.coeffs = {0.0, 0.0, 0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < d.size() && i < c.coeffs.size(); ++i) c.coeffs[i] = d[i];
}

}  // namespace celc
