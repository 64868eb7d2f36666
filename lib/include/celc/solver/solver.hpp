#pragma once
/// \file solver.hpp
/// Linear-velocity solvers for one window, as free functions with Options and
/// a Result. None of them prints, throws on data or aborts: a failure is a status.
///
/// Geometry (README "How the algorithm maps to the paper"): for a cluster with
/// start line l1 at t_s and end line l3 at t_e, and a motion model giving R(t)
/// and p(t) = P(t) v in the reference frame, let m1 = R(t_s) l1 and
/// m3 = R(t_e) l3 (plane normals in the reference frame). The image line at an
/// event time t_k, in the camera frame at t_k, is l_k = B_k v with
///   B_k = R_k^T ( m1 m3^T (P_e - P_k) - m3 m1^T (P_s - P_k) )
/// (the plane through the camera centre at t_k and the 3D line, i.e. the
/// intersection of the planes of l1 and l3), and the event's bearing
/// f_k = (x, y, 1) lies on it: f_k^T B_k v = 0 (the paper's CELC, its
/// event-line-line constraint). Row a_k = B_k^T f_k, stacked: A v = 0.
#include <cstdint>
#include <memory>
#include <vector>

#include "celc/geometry/motion_model.hpp"
#include "celc/solver/celc_residual.hpp"
#include "celc/solver/methods.hpp"
#include "celc/core/observations.hpp"
#include "celc/solver/options.hpp"
#include "celc/solver/result.hpp"
#include "celc/solver/sign.hpp"

namespace celc {

/// CELC linear: robust (Huber IRLS) nullspace of the stacked event rows,
/// geometric row normalisation, sign by cheirality, the window checks
/// (usable clusters, parallax) and the uniqueness check of the nullspace.
SolverResult solveCelcLinear(const WindowObservations& obs, const MotionModel& motion,
                             const LinearOptions& options);

/// CE3LC (the paper's baseline): per cluster with a middle line l2 at t_m the
/// rows of [l2]_x B_m v = 0, stacked, same robust nullspace, checks and sign test.
SolverResult solveCe3lc(const WindowObservations& obs, const MotionModel& motion,
                        const LinearOptions& options);

/// Ceres refinement of v on the unit sphere from `initial` (a unit vector):
/// minimises sum_k rho(d_k^2), d_k the event-to-transferred-line distance of
/// celc_residual.hpp [px], rho = Huber(huber_px). With refine_lines, each
/// cluster's l1 and l3 (2 DoF each, on the sphere) are refined jointly with v:
/// the maximum-likelihood estimate.
SolverResult refineVelocity(const WindowObservations& obs, const MotionModel& motion,
                            const Vec3& initial, bool refine_lines, const RefineOptions& options);

/// Seeds of a window's random event subsets: the linear stage's rows and the
/// refinement's events (per window, so that windows draw different subsets).
struct SampleSeeds {
  std::uint64_t linear_rows = 1;
  std::uint64_t refine_events = 1;
};

/// The estimates several methods share on one window: celc's linear
/// estimate, npt's, and celc_ml's with its end point. solveMethods computes
/// each on first use; given one of these, it keeps them for the next call on
/// the same observations, motion, seeds and solver options but
/// `uncertainty` (which they do not use), and takes them from it: `celc run`
/// solves celc_ml to redraw a window's clusters, then every method on the
/// clusters it kept. Move-only; empty when built.
class SharedSolves {
 public:
  SharedSolves();
  ~SharedSolves();
  SharedSolves(SharedSolves&&) noexcept;
  SharedSolves& operator=(SharedSolves&&) noexcept;
  struct Store;
  Store& store() { return *store_; }

 private:
  std::unique_ptr<Store> store_;
};

/// Runs the requested methods on one window; celc_opt and celc_ml start from
/// the celc result (computed once; also when its nullspace is ambiguous,
/// Degeneracy::NullspaceNotUnique: celc_opt then resolves the sign at its end
/// point), the window checks run once, and the
/// clusters' frames are computed once and shared by every method and sign test.
/// npt's sign is resolved with resolveSign when options.linear.resolve_sign.
/// celc's and ce3lc's ambiguous nullspaces are then answered where the
/// events fix the direction (LinearOptions::answer_when_observable). Every ok
/// result gets its sigma_deg (UncertaintyOptions). Results are in the order
/// of `methods`.
std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options, const SampleSeeds& seeds);
/// The same, the shared estimates taken from and kept in `shared` (SharedSolves).
/// With `threads` > 1 the methods run side by side once the estimates they
/// share are solved; each result depends on the window only, so the results
/// are the same for any count.
std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods, const SolverOptions& options,
                                       const SampleSeeds& seeds, SharedSolves& shared, int threads = 1);
/// The same with the seeds of the options (options.linear.seed, options.refine.seed).
std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options);

/// The window-level checks shared by every method: enough usable clusters and
/// parallax. Returns a Degenerate result, or one with status Ok when the window can be solved.
SolverResult checkWindow(const WindowObservations& obs, const MotionModel& motion,
                         const LinearOptions& options);

}  // namespace celc
