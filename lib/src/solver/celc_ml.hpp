#pragma once
// Internal: celc_ml, the joint refinement of v and every cluster's lines from
// several starts.
#include <cstdint>

#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

/// Whether npt's estimate may start celc_ml: npt's motion model (P(t) = tau I)
/// holds, exactly for GyroIntegrated in the reference frame, for a body-frame
/// model while
/// |w| max|tau| / 2 <= options.second_start_max_twist; and options.second_start.
bool nptStartApplies(const WindowObservations& obs, const MotionModel& motion,
                     const MlOptions& options);

/// The joint refinement from several starts, keeping the end point of lowest
/// robust cost: the CELC linear estimate `linear`; npt's (`npt`, null when
/// not used); options.ml.grid_starts directions of a hemisphere lattice. A
/// start within ml.second_start_deg of an end point already found is skipped.
/// With a lattice, the starts are refined on a seeded subset of
/// ml.screen_events events and only the winner on ml.max_events. The
/// winner keeps its start's singular values and sign margin; a lattice start's
/// sign is resolved by cheirality. Events drawn with event_seed.
SolverResult solveCelcMl(const WindowObservations& obs, const MotionModel& motion,
                         const SolverResult& linear, const SolverResult* npt,
                         const SolverOptions& options, const WindowFrames& frames,
                         std::uint64_t event_seed);

}  // namespace celc::detail
