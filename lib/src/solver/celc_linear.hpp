#pragma once
// Internal: CELC linear (solveCelcLinear) with the window's frames, the
// parallax test optional and the row seed explicit.
#include <cstdint>

#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

/// solveCelcLinear on the window's frames; rows drawn with row_seed (cluster
/// i of the usable ones with row_seed + i); the parallax test only with check_parallax.
SolverResult solveCelcLinear(const WindowObservations& obs, const MotionModel& motion,
                             const LinearOptions& options, const WindowFrames& frames,
                             bool check_parallax, std::uint64_t row_seed);

}  // namespace celc::detail
