#pragma once
/// \file solver.hpp
/// Linear-velocity solvers for one window, as free functions with Options and
/// a Result. None of them prints, throws on data or aborts: a failure is a status.
///
/// Geometry (README "Algorithm"): for a cluster with start line l1 at t_s and end
/// line l3 at t_e, and a motion model giving R(t) and p(t) = P(t) v in the
/// reference frame, let m1 = R(t_s) l1 and m3 = R(t_e) l3 (plane normals in the
/// reference frame). The image line at an event time t_k, in the camera frame at t_k, is
///   l_k = B_k v,  B_k = R_k^T [ m1 (P_e - P_k)^T m3 ... ]:
///   B_k = R_k^T ( m1 m3^T (P_e - P_k) - m3 m1^T (P_s - P_k) )
/// (the plane through the camera centre at t_k and the 3D line, i.e. the
/// intersection of the planes of l1 and l3), and the event's bearing
/// f_k = (x, y, 1) lies on it: f_k^T B_k v = 0 (the paper's CELC, its eq. for
/// the event-line-line constraint). Row a_k = B_k^T f_k, stacked: A v = 0.
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/solver/observations.hpp"

namespace celc {

/// Method names as used in every CSV, table and option.
enum class Method { Celc, CelcOpt, CelcMl, Ce3lc, Npt };
std::string toString(Method method);
/// Parses "celc", "celc_opt", "celc_ml", "ce3lc", "npt"; throws std::invalid_argument otherwise.
Method parseMethod(const std::string& name);
/// Parses a comma-separated list of method names.
std::vector<Method> parseMethodList(const std::string& list);
const std::vector<Method>& allMethods();

enum class SolveStatus { Ok, Degenerate, InvalidInput, Failed };
std::string toString(SolveStatus status);

/// Why a window is degenerate (status Degenerate), or None.
enum class Degeneracy { None, TooFewClusters, NoParallax, NullspaceNotUnique };
std::string toString(Degeneracy reason);

struct SolverResult {
  SolveStatus status = SolveStatus::Failed;
  Degeneracy degeneracy = Degeneracy::None;
  std::string message;            ///< human-readable detail when not ok
  Vec3 v = Vec3::Zero();          ///< unit linear velocity direction, reference camera frame
  double sigma_min = 0.0;         ///< smallest singular value of the final weighted system
  double sigma_second = 0.0;      ///< second smallest
  int iterations = 0;             ///< IRLS or Levenberg-Marquardt iterations
  int rows_used = 0;              ///< rows (events or line constraints) in the solve
  double residual_px = 0.0;       ///< robust residual scale (1.4826 MAD) [px]
  double sign_margin = 0.0;       ///< cheirality vote: (votes for - against) / clusters, in [0, 1] after resolution
  double time_us = 0.0;           ///< wall time of this method alone [us]
  bool ok() const { return status == SolveStatus::Ok; }
};

/// Options of the robust linear stage (CELC and CE3LC).
struct LinearOptions {
  int max_rows = 1000;           ///< random subset of event rows (0 = all) [rows]
  /// Share the rows equally among clusters (water-filling) instead of in
  /// proportion to their sizes. Off by default: on rendered scenes it let
  /// short, weakly informative clusters dominate (measured worse).
  bool balance_clusters = false;
  std::uint64_t seed = 1;        ///< seed of the row subset
  int max_iterations = 20;       ///< IRLS iterations
  double huber_k = 1.345;        ///< Huber threshold in units of the robust scale
  double tolerance = 1e-3;       ///< stop when the direction moves less than this [rad] (100x below the error at the paper's noise, 0.1 rad)
  /// Global start: the robust cost is scored on this many hemisphere
  /// directions (0 = off) and IRLS also runs from the best grid_starts of them.
  /// Off by default: on the paper's scene it changes the median error by < 2%
  /// and costs more than the rest of the solve.
  int grid_directions = 0;
  int grid_starts = 2;
  int grid_rows = 200;           ///< rows used to score the grid
  int min_clusters = 2;          ///< fewer usable clusters -> degenerate
  int min_cluster_events = 5;    ///< a cluster needs this many events to be usable
  /// A 2-D nullspace: sigma_min / sigma_second above this -> degenerate. The
  /// sigmas are RMS geometric residuals along the best and second-best
  /// directions; at the paper's default noise their ratio has median 0.34.
  double max_sigma_ratio = 0.9;
  /// A cluster shows parallax when its events, rotation-compensated, are this
  /// many times farther from one static line than from their transferred lines
  /// (robust scales); fewer than min_clusters such clusters -> degenerate.
  double min_parallax_ratio = 1.5;
  double min_parallax_px = 0.5;  ///< and the static-line scale exceeds this [px]
  /// Run the parallax test inside the solver. solveMethods runs it once per
  /// window and turns it off for the individual methods.
  bool check_parallax = true;
  bool resolve_sign = true;      ///< cheirality test; else the sign is arbitrary
  std::string validate() const;
};

/// Options of the Ceres refinement.
struct RefineOptions {
  double huber_px = 1.5;          ///< Huber loss threshold on the point-line distance [px]
  int max_iterations = 50;        ///< Levenberg-Marquardt iterations
  int max_events = 5000;          ///< events used (0 = all; else a seeded random subset)
  bool balance_clusters = false;  ///< share max_events equally among clusters (water-filling)
  std::uint64_t seed = 1;
  double function_tolerance = 1e-10;
  int num_threads = 1;
  std::string validate() const;
};

/// Options of the N-point linear solver `npt` (Gao et al., CVPR 2024; see npt.hpp).
struct NptOptions {
  int min_line_events = 5;   ///< a line needs this many events (>= 5: 6 homogeneous unknowns)
  int min_lines = 2;         ///< fewer lines with a partial velocity -> degenerate
  /// A line is dropped when its per-line system has no unique nullspace:
  /// (second smallest / largest singular value) below this.
  double min_line_sigma_ratio = 1e-10;
  /// The averaging stage: sigma_min / sigma_second above this -> degenerate.
  double max_sigma_ratio = 0.999;
  std::string validate() const;  ///< empty when valid
};

/// Options of the joint refinement `celc_ml` (v with every cluster's lines).
struct MlOptions {
  /// Also start from npt's estimate (sign resolved) when the celc start ends
  /// more than second_start_deg away from it, and keep the lower robust cost;
  /// also run from npt alone when celc fails. A remedy for the local minima of
  /// the joint problem (docs/peers.md). Only where npt's motion model holds:
  /// GyroIntegrated (P = tau I, exact), or a constant twist turning little,
  /// |w| max|tau| / 2 <= second_start_max_twist (npt's relative error on the
  /// displacement).
  bool second_start = true;
  double second_start_max_twist = 0.02;  ///< [-] |w| max|tau| / 2
  double second_start_deg = 2.0;         ///< [deg]
  /// Also start from this many directions of a hemisphere lattice (0 = off)
  /// and keep the end point of lowest robust cost; each start costs one joint
  /// refinement.
  int grid_starts = 0;
  /// With grid_starts: every start is refined on a seeded subset of this many
  /// events, and only the lowest-cost end point on all (refine.max_events) of
  /// them (0 = every start on all events).
  int screen_events = 1000;
  std::string validate() const;  ///< empty when valid
};

struct SolverOptions {
  LinearOptions linear;
  RefineOptions refine;
  NptOptions npt;
  MlOptions ml;
  std::string validate() const;
};

/// The schema of the `solver:` section and its parts (core/fields.hpp).
void describe(FieldVisitor& v, LinearOptions& options);
void describe(FieldVisitor& v, RefineOptions& options);
void describe(FieldVisitor& v, NptOptions& options);
void describe(FieldVisitor& v, MlOptions& options);
void describe(FieldVisitor& v, SolverOptions& options);

/// CELC linear: robust (Huber IRLS) nullspace of the stacked event rows,
/// geometric row normalisation, sign by cheirality, degeneracy checks.
SolverResult solveCelcLinear(const WindowObservations& obs, const MotionModel& motion,
                             const LinearOptions& options);

/// CE3LC (the paper's baseline): per cluster with a middle line l2 at t_m the
/// rows of [l2]_x B_m v = 0, stacked, same robust nullspace and sign test.
SolverResult solveCe3lc(const WindowObservations& obs, const MotionModel& motion,
                        const LinearOptions& options);

/// Ceres refinement of v on the unit sphere from `initial` (a unit vector):
/// minimises sum_k rho(d_k^2), d_k = focal * f_k^T B_k v / |(B_k v)_{1,2}| [px],
/// rho = Huber(huber_px). With refine_lines, each cluster's l1 and l3 (2 DoF
/// each, on the sphere) are refined jointly with v: the maximum-likelihood estimate.
SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& options);

/// Runs the requested methods on one window; celc_opt and celc_ml start from
/// the celc result (computed once), the cluster and parallax checks run once.
/// npt's sign is resolved with resolveSign when options.linear.resolve_sign.
/// Results are in the order of `methods`.
std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options);

/// The window-level checks shared by every method: enough usable clusters and
/// parallax. Returns a Degenerate result, or one with status Ok when the window can be solved.
SolverResult checkWindow(const WindowObservations& obs, const MotionModel& motion,
                         const LinearOptions& options);

/// Cheirality: the sign of v that puts the clusters' triangulated 3D lines in
/// front of the camera. Returns +1 or -1 and the vote margin in [-1, 1] for +v.
struct SignDecision {
  int sign = 1;
  double margin = 0.0;
};
SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v);

/// Angle between unit vectors [rad]; sign-agnostic variant min(phi, pi - phi).
double angleBetween(const Vec3& a, const Vec3& b);
double angleBetweenSignAgnostic(const Vec3& a, const Vec3& b);

}  // namespace celc
