#pragma once
// Internal: the Ceres refinement (refineVelocity) with the window's frames and
// the event subset explicit.
#include <cstdint>

#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

/// refineVelocity on the window's frames, over a seeded subset of max_events
/// events (0 = all; cluster i of the usable ones drawn with event_seed + i);
/// options.max_events and options.seed are not read.
SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& options,
                            const WindowFrames& frames, int max_events, std::uint64_t event_seed);

}  // namespace celc::detail
