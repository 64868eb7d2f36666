#pragma once
/// \file derotate.hpp
/// A window's events as the camera at one reference time sees them.
///
/// Under rotation an edge sweeps across the image (3 rad/s moves it 100-300
/// px in a 0.3 s window) and its events form a surface in (x, y, t) that
/// bends with the rotation; the growing then cuts it into pieces of a few
/// hundredths of a second each. Turned back by the gyro's rotation, an edge
/// moves only by the translation's parallax (the window's D, 3-25 px under
/// the parallax policy) and its events over the whole window lie on one
/// slowly moving line. Each event's bearing f = (x, y, 1) (undistorted) is
/// turned by R(t_ref)^T R(t) (motion_model.hpp: R(t) = R_ref_t) and projected
/// with the camera's focal lengths, without its distortion, about the centre
/// of the clustering's [0, 4096) px grid:
///   x' = fx g_x / g_z + kDerotatedCentrePx,  g = R(t_ref)^T R(t) f,
/// and y' alike, so that what the rotation turns off the sensor keeps
/// positive coordinates.
#include <vector>

#include "celc/cluster/to_observations.hpp"
#include "celc/core/types.hpp"
#include "celc/geometry/camera.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc {

/// Where the optical axis at t_ref lands in derotated coordinates [px].
inline constexpr double kDerotatedCentrePx = 2048.0;

/// The events with (x, y) replaced by their derotated position [px] (see the
/// file comment; t and polarity kept, same order). An event whose turned
/// bearing lies 60 deg or more from the optical axis at t_ref gets NaN
/// coordinates, and clusterEvents labels it noise, as it does one outside
/// [0, 4096) px (a focal length above about 1100 px). Deterministic; the rotation
/// is evaluated once per 50 us of event time.
std::vector<Event> derotateEvents(const std::vector<Event>& events, const BearingFunction& bearing,
                                  const CameraModel& camera, const MotionModel& motion, double t_ref);

}  // namespace celc
