#pragma once
// Internal: the cheirality sign test (celc/solver/sign.hpp) on frames
// computed once per window.
#include <cstddef>

#include "celc/solver/sign.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

/// Events that vote per cluster (evenly strided); a unanimous cluster is
/// decided after 7 of them.
constexpr size_t kSignVotesPerCluster = 12;

/// A cluster's vote weighs its line's rotation-free motion [px]
/// (geometry/line_motion.hpp), up to this.
constexpr double kSignFullWeightPx = 30.0;
/// ... times its lines' time span over this share of the window's, up to 1:
/// on rendered windows turning at 1-2 rad/s, clusters whose lines span less
/// than a tenth of the window voted wrong 40% of the time, longer ones 1-5%.
constexpr double kSignFullSpanShare = 0.5;
/// Events per cluster for the centroid at which that motion is measured.
constexpr size_t kSignCentroidEvents = 16;
/// resolveSign with the window's frames (frames of obs under motion).
SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v,
                         const WindowFrames& frames);
/// The same with a constant acceleration a (celc_acc.hpp; null: none): the
/// camera's position P(t) v + q(t) a, the depths odd in (v, a) together.
SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v, const Vec3* a,
                         const WindowFrames& frames);

}  // namespace celc::detail
