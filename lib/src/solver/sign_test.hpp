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

/// resolveSign with the window's frames (frames of obs under motion).
SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v,
                         const WindowFrames& frames);

}  // namespace celc::detail
