#pragma once
// Internal: the moving-line fit of line_fit.hpp (model "moving").
#include <cstddef>
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/lines/line_fit.hpp"

namespace celc::detail {

/// A cluster's events in the motion model's reference frame: g_j = R(t_j) f_j
/// (f_j = (x, y, 1) in the camera at t_j) and z_j = R(t_j) e_z, the optical
/// axis at t_j (for the point-to-line distance in the image at t_j).
struct DerotatedEvents {
  std::vector<Vec3> g;
  std::vector<Vec3> z;
};
DerotatedEvents derotate(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                         const MotionModel* motion);

/// Fits n(t) = n0 + (t - t_line) n1 to the events [begin, end) (Huber IRLS on
/// pixel distances, |n0| = 1) and returns the line at t_line in the camera
/// frame at t_line (R_line = R(t_line)). Thresholds are not applied.
FittedLine fitMovingLine(const std::vector<double>& times, const DerotatedEvents& events,
                         std::size_t begin, std::size_t end, double t_line, const Mat3& R_line,
                         double focal_px);

}  // namespace celc::detail
