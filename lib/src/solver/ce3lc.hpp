#pragma once
// Internal: CE3LC (solveCe3lc) with the window's frames and the parallax test optional.
#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

SolverResult solveCe3lc(const WindowObservations& obs, const MotionModel& motion,
                        const LinearOptions& options, const WindowFrames& frames,
                        bool check_parallax);

}  // namespace celc::detail
