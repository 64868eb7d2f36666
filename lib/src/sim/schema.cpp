// The schema of the simulators' options (core/fields.hpp).
#include "celc/sim/line_scene.hpp"

namespace celc {

void describe(FieldVisitor& v, LineSceneOptions& o) {
  v.field({"n_lines", "", "3D segments (clusters)", atLeast(1)}, o.n_lines);
  v.field({"events_per_line", "events", "events sampled per segment", atLeast(2)}, o.events_per_line);
  v.field({"duration", "s", "window length; t_s = 0, t_e = duration", above(0)}, o.duration);
  v.field({"velocity", "m/s", "v (body frame)", anyFinite()}, o.velocity);
  v.field({"omega", "rad/s", "angular velocity, camera frame", anyFinite()}, o.omega);
  v.field({"event_noise_px", "px", "std of event pixel noise", atLeast(0)}, o.event_noise_px);
  v.field({"line_noise_px", "px", "std of line endpoint noise", atLeast(0)}, o.line_noise_px);
  v.field({"omega_noise", "rad/s",
           "std per axis of the angular velocity given to the solvers",
           atLeast(0)},
          o.omega_noise);
  v.field({"outlier_fraction", "-",
           "share of events replaced by uniform random ones",
           withinBelow(0, 1)},
          o.outlier_fraction);
  v.field({"edge_offset_px", "px",
           "events moved this far off their line, to a side drawn per line",
           withinBelow(0, 100)},
          o.edge_offset_px);
  v.field({"acceleration", "m/s^2",
           "constant acceleration beyond the velocity (v is the velocity at the window's start), in a direction "
           "drawn per trial", atLeast(0)},
          o.acceleration);
  v.field({"x_range", "m", "segment endpoints x (reference frame)"}, o.x_range);
  v.field({"y_range", "m", "segment endpoints y"}, o.y_range);
  v.field({"z_range", "m", "segment endpoints z (depth)"}, o.z_range);
  v.section({"camera", "", "pinhole camera"}, [&](FieldVisitor& s) { describe(s, o.camera); });
  v.enumeration({"motion_model", "", "constant_twist (paper) or gyro_integrated"}, o.motion,
                {MotionModelKind::ConstantTwist, MotionModelKind::GyroIntegrated});
  v.field({"omega_wobble", "rad/s", "gyro_integrated: w(t) = omega + wobble sin(2 pi t / duration)"},
          o.omega_wobble);
  v.field({"gyro_rate_hz", "Hz", "gyro_integrated: gyro sampling rate", above(0)}, o.gyro_rate_hz);
  v.items({"fixed_segments", "", "these segments (reference frame) instead of random ones"}, o.fixed_segments,
          [](FieldVisitor& s, std::array<Vec3, 2>& seg) {
            s.require("start");
            s.require("end");
            s.field({"start", "m", "first endpoint"}, seg[0]);
            s.field({"end", "m", "second endpoint"}, seg[1]);
          });
}

}  // namespace celc
