#pragma once
// Internal: what the linear methods (CELC, CE3LC) and the window checks share:
// rejecting unusable options and input, and turning a robust nullspace into a
// result (uniqueness of the nullspace, sign).
#include <string>

#include "celc/solver/solver.hpp"
#include "constraint_rows.hpp"
#include "robust_nullspace.hpp"

namespace celc::detail {

/// A result with the status, reason and message only.
SolverResult failure(SolveStatus status, Degeneracy reason, std::string message);

/// True (and `result` set to InvalidInput) when the options are invalid, the
/// focal length is not positive or the rotation is not finite.
bool rejectInput(const WindowObservations& obs, const MotionModel& motion,
                 const LinearOptions& options, SolverResult& result);

/// The direction standard deviation [deg] that a linear result's two smallest
/// singular values imply over its rows_used rows (options.hpp,
/// max_nullspace_sigma_deg): 1 / sqrt(n (sigma_second^2 / sigma_min^2 - 1));
/// +inf when they are equal or sigma_second is not positive.
double impliedNullspaceSigmaDeg(double sigma_min, double sigma_second, int rows);

/// The result of a nullspace solution over `rows` rows: Failed when it did not
/// converge; Degenerate (NullspaceNotUnique) when
/// the direction std the singular values imply exceeds
/// options.max_nullspace_sigma_deg (options.hpp); else Ok with v unit and,
/// with options.resolve_sign, its sign resolved by the cheirality test.
SolverResult nullspaceResult(const NullspaceSolution& solution, const WindowObservations& obs,
                             const MotionModel& motion, const LinearOptions& options, int rows,
                             const WindowFrames& frames);

}  // namespace celc::detail
