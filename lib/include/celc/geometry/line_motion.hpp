#pragma once
/// \file line_motion.hpp
/// How far a cluster's boundary line moved over the cluster, rotation removed:
/// the parallax its events carry.
#include <cstddef>

#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"

namespace celc {

/// The motion of a cluster's line between l1 (at t1) and l3 (at t3) that the
/// rotation does not explain [px]: both lines turned into the reference frame
/// of `motion` (m = R(t) l), the signed point-line distances
/// s_i = m_i . c / |(m_i)_xy| of the centroid c of the cluster's events there
/// (each event's bearing turned by R(t) and put on the plane z = 1; about
/// `centroid_events` events, evenly spread), and |s1 - s3| times focal_px.
/// NaN when the cluster has no lines or no event in front of the reference camera.
double lineMotionPx(const ClusterObservation& cluster, const MotionModel& motion, double focal_px,
                    std::size_t centroid_events = 64);

}  // namespace celc
