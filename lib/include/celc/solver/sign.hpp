#pragma once
/// \file sign.hpp
/// The cheirality sign test: v and -v satisfy every linear constraint alike;
/// only one puts the clusters' 3D lines in front of the camera.
#include "celc/geometry/motion_model.hpp"
#include "celc/core/observations.hpp"

namespace celc {

/// The sign to apply to v (+1 or -1) and the clusters' weighted vote margin
/// for +v, (weight for - weight against) / total weight, in [-1, 1].
struct SignDecision {
  int sign = 1;
  double margin = 0.0;
};

/// For sampled events of each cluster (at least 2 events, l3 after l1), the
/// depth along the event's ray where it meets the planes of l1 and l3,
///   lambda = sum_i (m_i.f')(m_i.(P_i v - P_k v)) / sum_i (m_i.f')^2,  f' = R_k f_k,
/// is odd in v; each cluster votes for the sign its majority of events puts in
/// front (lambda > 0), weighted by how far its line moved once the rotation is
/// removed (lineMotionPx, at most 30 px: a line that hardly moved gives a
/// depth of noise); when the weights tie, the balance of events decides.
SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v);

}  // namespace celc
