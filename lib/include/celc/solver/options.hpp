#pragma once
/// \file options.hpp
/// Options of the solvers, one struct per stage, each with a validate() that
/// returns what is wrong (empty when valid). The defaults are what `celc run`,
/// `celc solve` and the Python module use; SolverOptions::paper() is the
/// preset of the paper's and the peers' simulation studies. docs/method.md
/// gives the measurements behind both.
#include <cstdint>
#include <string>

#include "celc/core/fields.hpp"

namespace celc {

/// Options of the robust linear stage (CELC and CE3LC) and of the window checks.
struct LinearOptions {
  int max_rows = 1000;           ///< random subset of event rows (0 = all) [rows]
  /// Share the rows equally among clusters (water-filling) instead of in
  /// proportion to their sizes. Off: short, weakly informative clusters then dominate.
  bool balance_clusters = false;
  std::uint64_t seed = 1;        ///< seed of the row subset (solveMethods' SampleSeeds override it per window)
  int max_iterations = 20;       ///< IRLS iterations
  double huber_k = 1.345;        ///< Huber threshold in units of the robust scale
  /// After the Huber IRLS converges, IRLS with Tukey's biweight at this many
  /// robust scales (0 = off), from the Huber end point: rows beyond it get no
  /// weight. Huber keeps a bounded pull of every far row; on rendered
  /// clusters that hold a few per cent of another edge's events (at corners)
  /// those rows together move the direction far off (docs/method.md).
  double tukey_k = 3.0;
  /// Stop when the direction moves less than this [rad]; well below the
  /// direction error at realistic noise.
  double tolerance = 1e-3;
  /// Global start: the robust cost is scored on this many hemisphere
  /// directions (0 = off) and IRLS also runs from the best grid_starts of them:
  /// on clustered real or rendered events the robust cost has local minima
  /// that the single start from the plain generalised eigenvector falls into.
  /// The paper's scene needs no grid (SolverOptions::paper()).
  int grid_directions = 256;
  int grid_starts = 4;
  int grid_rows = 200;           ///< rows used to score the grid
  int min_clusters = 2;          ///< fewer usable clusters -> degenerate
  int min_cluster_events = 5;    ///< a cluster needs this many events to be usable
  /// A 2-D nullspace: degenerate when the direction's standard deviation that
  /// the two smallest singular values imply exceeds this [deg]. With sigma_min,
  /// sigma_second the RMS geometric residuals along the best and second-best
  /// directions over n rows, the cost rises by n (sigma_second^2 - sigma_min^2)
  /// from one to the other, so the direction's standard deviation is about
  /// 1 / sqrt(n (sigma_second^2 / sigma_min^2 - 1)) [rad]: a fixed ratio would
  /// call a window with many events degenerate though it fixes v well.
  double max_nullspace_sigma_deg = 30.0;
  /// An ambiguous nullspace (above) is still answered when the window's
  /// events fix the direction: the bound at the ambiguous direction
  /// (direction_information.hpp: Fisher information of every event with the
  /// lines as nuisance, at the residuals' robust scale) is at most
  /// max_nullspace_sigma_deg. These rows then determine v poorly although the
  /// data do not, so the answer's sigma_deg is at least the std the rows imply.
  /// A step of solveMethods (the standalone solveCelcLinear / solveCe3lc give
  /// the rows' own verdict). Off: such a window is degenerate
  /// (nullspace_not_unique) for the method.
  bool answer_when_observable = true;
  /// A cluster shows parallax when its events, rotation-compensated, are this
  /// many times farther from one static line than from a line moving linearly
  /// in time (robust scales); fewer than min_clusters such clusters -> degenerate.
  double min_parallax_ratio = 1.5;
  double min_parallax_px = 0.5;  ///< and the static-line scale exceeds this [px]
  /// The window's parallax (the median over its clusters of the static /
  /// moving ratio above) below this -> degenerate / no_parallax, however many
  /// single clusters pass: a window the rotation explains (pure rotation)
  /// has a median near 1 even when a few noisy clusters pass (docs/accuracy.md).
  double min_window_parallax = 1.1;
  /// ... applied to windows with at least this many measured clusters (with
  /// fewer, the per-cluster test alone decides, as it always did).
  int min_window_parallax_clusters = 6;
  bool resolve_sign = true;      ///< cheirality test; else the sign is arbitrary
  std::string validate() const;
};

/// Options of the Ceres refinement.
struct RefineOptions {
  double huber_px = 1.5;          ///< Huber loss threshold on the point-line distance [px]
  int max_iterations = 50;        ///< Levenberg-Marquardt iterations
  int max_events = 5000;          ///< events used (0 = all; else a seeded random subset)
  bool balance_clusters = false;  ///< share max_events equally among clusters (water-filling)
  std::uint64_t seed = 1;         ///< seed of the event subset (solveMethods' SampleSeeds override it per window)
  double function_tolerance = 1e-10;
  int num_threads = 1;
  /// celc_opt: then a last refinement under a Cauchy loss with c = cauchy_scale
  /// times the residuals' robust scale (1.4826 median |d|), when more than
  /// cauchy_min_tail of them lie beyond 3 robust scales (0 = off).
  double cauchy_scale = 1.0;      ///< [-]
  double cauchy_min_tail = 0.01;  ///< [-]
  /// > 0: that last refinement uses Tukey's biweight at tukey_scale robust
  /// scales instead of the Cauchy loss: an event beyond has no pull at all,
  /// where under Cauchy many far events of other edges together still move v
  /// (docs/method.md). cauchy_scale = 0 still turns the last refinement off.
  double tukey_scale = 3.0;       ///< [-]
  /// celc_opt: starts of the refinement, the linear estimate on this many
  /// random row subsets (the first is celc's own; one within 1 deg of an
  /// earlier one is dropped). With several, each is refined under Huber on
  /// screen_events events, and the one with the lowest cost there is refined
  /// as a single start is.
  int starts = 4;
  int screen_events = 1000;  ///< [events] (0 = max_events)
  std::string validate() const;
};

/// npt's time origin t0: each event's row is [(s(t) - s(t0)) f'^T, f'^T]
/// (npt.hpp), so the per-line unknown m is the line's moment about the
/// camera centre at t0.
enum class NptTimeOrigin {
  Centre,      ///< the midpoint of the window's first and last event times
  FirstEvent,  ///< the window's first event (the published code's)
};
/// How a line's solution x = [d x v; m] is scaled before its averaging row is
/// formed; the row's length, hence its weight in the averaging, is |d x v|
/// after scaling.
enum class NptLineNormalisation {
  Vector,  ///< |x| = 1: weight |d x v| / sqrt(|d x v|^2 + |m|^2)
  Moment,  ///< |m| = 1 (the published code's): weight |d x v| / |m|
};
std::string toString(NptTimeOrigin origin);                ///< "centre" | "first_event"
std::string toString(NptLineNormalisation normalisation);  ///< "vector" | "moment"

/// Options of the N-point linear solver `npt` (Gao et al., CVPR 2024; see npt.hpp).
/// The published variant: time_origin FirstEvent, line_normalisation Moment.
struct NptOptions {
  int min_line_events = 5;   ///< a line needs this many events (>= 5: 6 homogeneous unknowns)
  int min_lines = 2;         ///< fewer lines with a partial velocity -> degenerate
  /// A line is dropped when its per-line system has no unique nullspace:
  /// (second smallest / largest singular value) below this.
  double min_line_sigma_ratio = 1e-10;
  /// The averaging stage: sigma_min / sigma_second above this -> degenerate.
  double max_sigma_ratio = 0.999;
  NptTimeOrigin time_origin = NptTimeOrigin::Centre;
  NptLineNormalisation line_normalisation = NptLineNormalisation::Vector;
  std::string validate() const;  ///< empty when valid
};

/// Options of the joint refinement `celc_ml` (v with every cluster's lines).
struct MlOptions {
  /// Also start from npt's estimate (sign resolved) when the celc start ends
  /// more than second_start_deg away from it, and keep the lower robust cost;
  /// also run from npt alone when celc fails. A remedy for the local minima of
  /// the joint problem (docs/accuracy.md). Only where npt's motion model holds:
  /// GyroIntegrated in the reference frame (P = tau I, exact), or a body-frame
  /// model (constant twist, gyro-integrated) turning little,
  /// |w| max|tau| / 2 <= second_start_max_twist (npt's relative error on the
  /// displacement).
  bool second_start = true;
  double second_start_max_twist = 0.02;  ///< [-] |w| max|tau| / 2
  double second_start_deg = 2.0;         ///< [deg]
  /// Also start from this many directions of a hemisphere lattice (0 = off)
  /// and keep the end point of lowest robust cost; each start costs one joint
  /// refinement.
  int grid_starts = 8;
  /// Events of the joint problem: a seeded subset of about this many (0 =
  /// all), drawn as refine.max_events draws celc_opt's; recorded windows hold
  /// 10^4-10^6 events (docs/method.md, "celc_ml's event budget").
  int max_events = 40000;
  /// With several starts, each is refined on every k-th event of the
  /// joint problem's subset, k chosen so that about this many are used, and
  /// only the lowest-cost end point on all (max_events) of them
  /// (0 = every start on all events).
  int screen_events = 4000;
  /// Also start from the lowest local minima of the line profile J(v), the
  /// algebraic event-line cost with every cluster's line eliminated in closed
  /// form (no fitted lines; docs/accuracy.md): J on a hemisphere lattice of
  /// profile_lattice directions (0 = off), a pattern search from the
  /// profile_starts lowest separated points, profile_events events per
  /// cluster summed into J (0 = all).
  int profile_lattice = 100;
  int profile_starts = 3;
  int profile_events = 100;
  /// With several starts, each runs this many Levenberg-Marquardt iterations
  /// (0 = refine.max_iterations) and only the lowest-cost one continues to
  /// convergence.
  int start_iterations = 8;
  /// ... then the finalists, this many lowest end points of the starts,
  /// are each refined to convergence on all max_events events and the
  /// lowest converged cost wins (1 = the screen's winner alone).
  int finalists = 3;
  /// End points whose robust cost is within cheiral_tie units of the lowest,
  /// N (C - C_min) / C_min over the N events of the cost (a likelihood-ratio
  /// scale under Gaussian noise), are tied: among them the one whose
  /// clusters agree best on the side of the camera their lines lie
  /// (|sign margin| of resolveSign, sign.hpp) wins, in the screen and among
  /// the finalists (0 = the lowest cost always). 6: about the 95% point of
  /// the chi-square law with 2 degrees of freedom (5.99), the direction's
  /// two in which two basins differ.
  double cheiral_tie = 6.0;  ///< [-]
  /// The scene lies in front of the camera: an answer whose clusters'
  /// cheirality votes disagree, |sign margin| below cheiral_min (resolveSign,
  /// sign.hpp; 1 = unanimous), is replaced by the lowest-cost screened end
  /// point whose margin reaches it, refined to convergence, if that end
  /// point's cost lies within cheiral_clusters clusters' share of the lowest,
  /// K (C - C_min) / C_min over the K clusters: a lead that the errors of a
  /// few impure clusters can make (docs/method.md, "celc_ml's answer in
  /// front of the camera"); 0 = off.
  double cheiral_min = 0.9;       ///< [-] in [0, 1]
  double cheiral_clusters = 10.0;  ///< [-] clusters' share of the cost
  /// The Huber threshold of the joint cost becomes huber_scale times the
  /// robust scale (1.4826 MAD) of the residuals at the first start's end
  /// point when that exceeds refine.huber_px (0 = refine.huber_px always).
  /// Huber's estimator keeps ~95% of least squares' efficiency under Gaussian
  /// noise at 1.345 sigma, ~99% at 2 sigma.
  double huber_scale = 2.0;  ///< [-]
  /// The winner's end point is then refined once more under a Cauchy loss,
  /// rho(d) = c^2 log(1 + d^2 / c^2) with c = cauchy_scale times the robust
  /// scale of its residuals (0 = off): a redescending loss, so that events of
  /// another edge inside a cluster stop pulling its line (Huber's pull stays
  /// constant with distance, Cauchy's falls as c^2 / d). 2.385 keeps ~95% of
  /// least squares' efficiency under Gaussian noise.
  double cauchy_scale = 2.4;  ///< [-]
  /// ... only when more than this share of the winner's residuals lie beyond
  /// 3 robust scales (Gaussian noise puts 0.27% there): without such a tail
  /// Huber's estimate is kept, since Cauchy's cost is flatter where a window
  /// is weakly observed.
  double cauchy_min_tail = 0.01;  ///< [-]
  /// > 0: that last refinement uses Tukey's biweight at tukey_scale robust
  /// scales instead of the Cauchy loss, rho(d) = c^2 / 3 (1 - (1 - d^2 /
  /// c^2)^3) within c and c^2 / 3 beyond: an event of another edge has no
  /// pull at all, where under Cauchy many of them together still move v
  /// (docs/method.md, "celc_ml's last refinement under Tukey's biweight").
  /// cauchy_scale = 0 still turns the last refinement off.
  double tukey_scale = 3.0;  ///< [-]
  /// > 0: after that last refinement, the cluster whose events disagree most
  /// with the other clusters' is left out and v refined again, while one's
  /// statistic exceeds this, at most a tenth of the clusters (at least one):
  /// T_k of JointProblem::clusterAgreement, how far leaving the cluster out
  /// would move v against the noise's spread of that move, a chi-square
  /// value of up to 2 degrees of freedom. A cluster whose one moving line
  /// moves as no v explains (two edges that meet at a small angle, grown into
  /// one region) biases v, and Tukey's loss cannot let it go: its events lie
  /// near their line. 0 = off.
  double cluster_test = 0.0;  ///< [-]
  /// Also estimate a constant offset of the given angular velocity (a
  /// gyroscope bias) with v, kept where a likelihood-ratio test (p = 0.001)
  /// finds one (solver/rate_offset.hpp; docs/method.md): some 30-60 joint
  /// refinements more per window.
  bool rate_offset = false;
  std::string validate() const;  ///< empty when valid
};

/// The uncertainty reported with every estimate (SolverResult::sigma_deg):
/// the standard deviation of the direction sqrt(trace C) from the Fisher
/// information of the event-line likelihood at the estimate and the fitted
/// lines, C = s^2 S^-1 with s the robust scale of the residuals there
/// (direction_information.hpp), times a per-method factor. The factors
/// calibrate the Fisher value (the ML bound) to each method's actual spread,
/// so that about 9 in 10 windows have phi <= 2 sigma (docs/accuracy.md).
/// The budget terms add what the Fisher value cannot see of a gyroscope's and
/// a calibration's errors: sigma_deg = sqrt((factor sigma_F)^2 + sigma_B^2).
///
/// The Fisher value sees the noise, not a model that fails (a rotation that
/// is not constant, clusters that mix edges, a wrong basin): with
/// `agreement`, estimates of the same window are compared. Witnesses are the
/// estimates of celc, celc_opt and celc_ml in the window (celc's also when
/// only celc_opt or celc_ml was asked for, which start from it); two
/// estimates i, j disagree when their angle exceeds
/// 2 sqrt(sigma_i^2 + sigma_j^2) (Fisher values), and then each method's
/// sigma_deg is at least the largest angle to a witness it disagrees with.
/// ce3lc and npt are not witnesses: their sigma_deg is not a calibrated
/// standard deviation, so their disagreements are not evidence.
struct UncertaintyOptions {
  bool enabled = true;          ///< compute sigma_deg (off: NaN)
  bool agreement = true;        ///< raise sigma_deg to the angle to a disagreeing witness
  /// A linear witness (celc's estimate, the witness_rows subset) raises
  /// celc_opt's and celc_ml's sigma_deg too. Off: only the refined estimates
  /// witness for each other; they start from the linear estimate, and moving
  /// away from it is their refinement's work (docs/decisions.md).
  bool linear_witness_refined = false;
  /// > 0 (with agreement): one more witness, the linear celc estimate on a
  /// second random subset of this many rows [rows]. Where the linear cost is
  /// flat (model errors: impure clusters, an accelerating camera) such
  /// subsets scatter, while the window's own estimates may share one bias.
  int witness_rows = 0;
  /// > 0: an ok estimate of celc, celc_opt or celc_ml whose clusters'
  /// cheirality votes agree less than this (|sign margin| of resolveSign at
  /// the estimate, sign.hpp; 1 = unanimous) gets a sigma_deg of at least
  /// 61.2 deg, the RMS angle of a random direction to a fixed one: the
  /// scene must lie in front of the camera, and such answers were measured
  /// wrong (docs/accuracy.md, "Answers behind the camera").
  double cheiral_min = 0.9;  ///< [-] in [0, 1]
  int max_events = 2000;        ///< events used per window (regular stride; 0 = all)
  double scale_celc = 2.5;      ///< [-] factor for method celc
  double scale_celc_opt = 2.5;  ///< [-] for celc_opt
  double scale_celc_ml = 1.0;   ///< [-] for celc_ml (the ML estimate: the Fisher value itself)
  double scale_ce3lc = 8.0;     ///< [-] for ce3lc (not calibrated: heavy-tailed errors)
  double scale_npt = 30.0;      ///< [-] for npt (not calibrated: heavy-tailed errors)
  /// The model-error budget (solver/error_budget.hpp): 1-sigma sizes of the
  /// errors the estimate takes as exact, propagated to the direction and
  /// added in quadrature to the Fisher value. 0 leaves a source out.
  double gyro_bias_rad_s = 0.01;    ///< [rad/s] per axis, a constant rate offset
  double gyro_scale = 0.01;         ///< [-] per axis, a rate scale error
  double imu_rotation_deg = 1.0;    ///< [deg] about each axis, the IMU-camera rotation
  double principal_point_px = 3.0;  ///< [px] per image axis
  double focal_share = 0.01;        ///< [-] relative focal length error
  /// Every budget size 0: inputs known to be exact (simulated windows).
  void clearBudget() { gyro_bias_rad_s = gyro_scale = imu_rotation_deg = principal_point_px = focal_share = 0.0; }
  std::string validate() const;  ///< empty when valid
};

/// celc_acc: CELC with a constant acceleration (docs/method.md, "celc_acc").
/// The joint refinement of v, a and the lines is kept where the window
/// shows an acceleration; elsewhere the answer is celc_ml's, and the
/// result says why (Degeneracy::AccelerationUnobservable).
struct AccOptions {
  /// Fewer usable lines than this: a is not observable (each line fixes
  /// three of the five unknowns of v and a; three lines leave four checks).
  int min_lines = 3;
  /// a (over the speed) is observable when its standard deviation along its
  /// worst-fixed direction, times the longest |t - t_ref| of the window's
  /// events, is at most this [-]: 1 = the window cannot tell a velocity
  /// change of the velocity's own size over it.
  double max_sigma = 1.0;
  /// The acceleration is seen when the likelihood ratio of the costs without
  /// and with it, 2 (C_0 - C_a) / s^2 (s the residuals' robust scale), exceeds
  /// this: the chi-square law's point with 3 degrees of freedom (a's) at
  /// p = 0.001 is 16.27.
  double test_chi2 = 16.27;  ///< [-]
  /// With an accelerometer (WindowObservations::accelerometer): an
  /// accelerating answer a (over the speed) whose direction the measured
  /// acceleration a_m contradicts is not kept. The statistic
  /// r^T (sigma^2 I + s^2 C_a)^-1 r, r = a_m - s a, s = max(0, a_m.a / |a|^2)
  /// the speed that fits best and C_a a's covariance, is about chi-square
  /// with 2 degrees of freedom where they agree: its point at p = 0.001 is
  /// 13.82. And where |a_m| is at least accelerometer_start_sigma times its
  /// sigma, the joint refinement also starts from a along a_m.
  double accelerometer_chi2 = 13.82;     ///< [-]
  double accelerometer_start_sigma = 3.0;  ///< [-]
  std::string validate() const;  ///< empty when valid
};

/// The options of every solver. The defaults suit clustered real or rendered
/// events (`celc run`, `celc solve`, Python): global starts for the linear
/// stage and the joint refinement, whose costs have local minima there; a
/// large event budget for celc_ml, with its three lowest screened basins
/// refined to convergence; Tukey's biweight in the linear stage and in
/// celc_opt's and celc_ml's last refinements, for clusters that hold a few
/// per cent of another edge's events; celc_opt started from celc on 4 random
/// row subsets; celc_ml's answer kept in front of the camera (docs/method.md,
/// "Library defaults and the paper's preset").
struct SolverOptions {
  /// The preset of the paper's simulation study (`celc simulate`) and the
  /// peers' study: a single start, Huber losses, celc_ml on 5000 events, no
  /// cheirality floor. Their scenes hold a few thousand clean events, where
  /// the defaults' starts and redescending stages only cost time.
  static SolverOptions paper();

  LinearOptions linear;
  RefineOptions refine;
  NptOptions npt;
  MlOptions ml;
  AccOptions acc;
  UncertaintyOptions uncertainty;
  /// Run the parallax test of the window checks (solveMethods, once per
  /// window). Off where every window is known to move and outliers would
  /// inflate the test's robust scales (the peer study).
  bool check_parallax = true;
  std::string validate() const;
};

/// The schema of the `solver:` section and its parts (core/fields.hpp).
void describe(FieldVisitor& v, LinearOptions& options);
void describe(FieldVisitor& v, RefineOptions& options);
void describe(FieldVisitor& v, NptOptions& options);
void describe(FieldVisitor& v, MlOptions& options);
void describe(FieldVisitor& v, AccOptions& options);
void describe(FieldVisitor& v, UncertaintyOptions& options);
void describe(FieldVisitor& v, SolverOptions& options);

}  // namespace celc
