#pragma once
/// \file result.hpp
/// What a solver returns for one window: a status (never an exception on
/// data), the direction and what the solve saw.
#include <cmath>
#include <string>

#include "celc/core/types.hpp"

namespace celc {

enum class SolveStatus { Ok, Degenerate, InvalidInput, Failed };
std::string toString(SolveStatus status);

/// Why a window is degenerate (status Degenerate), or None.
/// AccelerationUnobservable: celc_acc's window cannot fix an acceleration
/// (too few lines, too short a window); its answer is then the
/// constant-velocity one (status ok) and the message says why.
enum class Degeneracy { None, TooFewClusters, NoParallax, NullspaceNotUnique, AccelerationUnobservable };
std::string toString(Degeneracy reason);

struct SolverResult {
  SolveStatus status = SolveStatus::Failed;
  Degeneracy degeneracy = Degeneracy::None;
  std::string message;            ///< human-readable detail when not ok
  /// Unit linear velocity direction, reference camera frame. Not an estimate
  /// unless ok(): a linear method whose nullspace is not unique
  /// (Degeneracy::NullspaceNotUnique) leaves its ambiguous direction here, sign
  /// unresolved, which celc_opt and celc_ml still start from.
  Vec3 v = Vec3::Zero();
  double sigma_min = 0.0;         ///< smallest singular value of the final weighted system
  double sigma_second = 0.0;      ///< second smallest
  int iterations = 0;             ///< IRLS or Levenberg-Marquardt iterations
  int rows_used = 0;              ///< rows (events or line constraints) in the solve
  double residual_px = 0.0;       ///< robust residual scale (1.4826 MAD) [px]
  double sign_margin = 0.0;       ///< cheirality vote: (votes for - against) / clusters, in [0, 1] after resolution
  double time_us = 0.0;           ///< wall time of this method alone [us]
  /// Standard deviation of the direction [deg] (solver/direction_information.hpp,
  /// SolverOptions::uncertainty): set by solveMethods for ok results; +inf when
  /// the direction is unobservable at the estimate, NaN when not computed.
  double sigma_deg = NAN;
  /// sigma_deg's parts [deg]: the Fisher value times the method's factor, and
  /// the model-error budget (solver/error_budget.hpp); NaN when not computed.
  double sigma_fisher_deg = NAN;
  double sigma_budget_deg = NAN;
  /// The rule that raised sigma_deg above hypot(sigma_fisher_deg,
  /// sigma_budget_deg), empty when none: "disagreement" (another estimate of
  /// the window disagrees), "behind_camera" (the clusters' cheirality votes
  /// disagree), "ambiguous_nullspace" (the linear rows' own spread),
  /// "accelerometer_refused" (sigma_floor_deg).
  std::string sigma_rule;
  /// A floor of sigma_deg [deg] the method sets itself, 0 for none. celc_acc
  /// where the accelerometer refused the acceleration the events show: the
  /// angle between its constant-velocity answer and the refused one (the
  /// events fit neither model well).
  double sigma_floor_deg = 0.0;
  /// The window's measured parallax, shared by every method (solveMethods):
  /// the median over the clusters with >= 8 events of the ratio of the robust
  /// scales of the rotation-compensated events about one static line and about
  /// a line moving linearly in time [-] (1: no parallax; the test needs
  /// min_parallax_ratio). NaN when the test did not run.
  double parallax = NAN;
  int n_lines = 0;                ///< usable clusters of the window (shared by every method)
  /// celc_acc only: the constant acceleration over the speed, a / |v| [1/s],
  /// reference frame, of the joint refinement (NaN for the other methods and
  /// where it did not run), and whether the window shows it (a likelihood-ratio
  /// test of the costs with and without it, SolverOptions::acc; when not, v is
  /// the constant-velocity answer).
  Vec3 acceleration = Vec3::Constant(NAN);
  bool acceleration_seen = false;
  bool ok() const { return status == SolveStatus::Ok; }
};

/// Angle between unit vectors [rad], atan2(|a x b|, a.b); the sign-agnostic
/// variant is min(phi, pi - phi).
double angleBetween(const Vec3& a, const Vec3& b);
double angleBetweenSignAgnostic(const Vec3& a, const Vec3& b);

}  // namespace celc
