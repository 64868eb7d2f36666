#pragma once
// Internal: celc_ml, the joint refinement of v and every cluster's lines from
// several starts.
#include <cstdint>
#include <vector>

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
/// With `end`: the winner's lines under the Huber loss (before a last
/// Cauchy / Tukey stage) and that loss's threshold [px], which celc_acc
/// starts from; not valid where the answer is no joint refinement's or came
/// with a rate offset (its lines belong to another motion).
struct MlEnd {
  std::vector<Vec3> m1, m3;
  double huber_px = 0.0;
  bool valid = false;
};
SolverResult solveCelcMl(const WindowObservations& obs, const MotionModel& motion,
                         const SolverResult& linear, const SolverResult* npt,
                         const SolverOptions& options, const WindowFrames& frames,
                         std::uint64_t event_seed, MlEnd* end = nullptr);

}  // namespace celc::detail
