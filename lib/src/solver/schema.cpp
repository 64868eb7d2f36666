// The schema of the solvers' options (core/fields.hpp).
#include "celc/solver/options.hpp"

namespace celc {

void describe(FieldVisitor& v, LinearOptions& o) {
  v.field({"max_rows", "rows", "random subset of event rows (0 = all)", atLeast(0)}, o.max_rows);
  v.field({"balance_clusters", "", "share the rows equally among clusters"}, o.balance_clusters);
  v.field({"seed", "", "seed of the row subset"}, o.seed);
  v.field({"max_iterations", "", "IRLS iterations", atLeast(1)}, o.max_iterations);
  v.field({"huber_k", "-", "Huber threshold in robust scales", above(0)}, o.huber_k);
  v.field({"tukey_k", "-",
           "then IRLS with Tukey's biweight at this many robust scales, from the Huber end point (0 = off)",
           atLeast(0)},
          o.tukey_k);
  v.field({"tolerance", "rad", "IRLS stops when the direction moves less", above(0)}, o.tolerance);
  v.field({"grid_directions", "",
           "global start: hemisphere directions scored (0 = off)", atLeast(0)},
          o.grid_directions);
  v.field({"grid_starts", "", "IRLS also runs from the best this many of them", atLeast(0)}, o.grid_starts);
  v.field({"grid_rows", "rows", "rows used to score the directions", atLeast(1)}, o.grid_rows);
  v.field({"min_clusters", "", "fewer usable clusters -> degenerate", atLeast(1)}, o.min_clusters);
  v.field({"min_cluster_events", "events", "a cluster needs this many events to be usable", atLeast(2)},
          o.min_cluster_events);
  v.field({"max_nullspace_sigma_deg", "deg",
           "degenerate when the two smallest singular values imply a direction std above this", above(0)},
          o.max_nullspace_sigma_deg);
  v.field({"answer_when_observable", "",
           "answer such an ambiguous nullspace when the events' bound at its direction is below that std "
           "(sigma_deg then at least the rows' std)"},
          o.answer_when_observable);
  v.field({"min_parallax_ratio", "-", "static-line / moving-line residual below this -> no parallax", atLeast(1)},
          o.min_parallax_ratio);
  v.field({"min_parallax_px", "px", "and the static-line residual must exceed this", atLeast(0)}, o.min_parallax_px);
  v.field({"min_window_parallax", "-",
           "median static/moving ratio over the clusters below this -> no parallax", atLeast(0)},
          o.min_window_parallax);
  v.field({"min_window_parallax_clusters", "", "... in windows with at least this many measured clusters"},
          o.min_window_parallax_clusters);
  v.field({"resolve_sign", "", "cheirality test; else the sign is arbitrary"}, o.resolve_sign);
}

namespace {

/// The keys of a last refinement under the Cauchy loss (celc_opt's in
/// `refine`, celc_ml's in `ml`): its scale and the residual tail it needs.
void describeCauchyStage(FieldVisitor& v, const char* scale_doc, double& scale, double& min_tail) {
  v.field({"cauchy_scale", "-", scale_doc, atLeast(0)}, scale);
  v.field({"cauchy_min_tail", "-",
           "... only when more than this share of the residuals lie beyond 3 robust scales (Gaussian noise: 0.0027)",
           within(0, 1)},
          min_tail);
}

}  // namespace

void describe(FieldVisitor& v, RefineOptions& o) {
  v.field({"huber_px", "px", "Huber threshold on the point-line distance", above(0)}, o.huber_px);
  v.field({"max_iterations", "", "Levenberg-Marquardt iterations", atLeast(1)}, o.max_iterations);
  v.field({"max_events", "events", "seeded subset of events (0 = all)", atLeast(0)}, o.max_events);
  v.field({"balance_clusters", "", "share max_events equally among clusters"}, o.balance_clusters);
  v.field({"seed", "", "seed of the event subset"}, o.seed);
  v.field({"function_tolerance", "-", "Ceres' relative cost change to stop", above(0)}, o.function_tolerance);
  v.field({"num_threads", "", "Ceres threads per solve", atLeast(1)}, o.num_threads);
  describeCauchyStage(v,
                      "celc_opt: then a last refinement under a Cauchy loss at this times the residuals' robust "
                      "scale: a cluster whose line is off stops pulling (0 = off)",
                      o.cauchy_scale, o.cauchy_min_tail);
  v.field({"tukey_scale", "-",
           "celc_opt: > 0: that last refinement uses Tukey's biweight at this times the robust scale instead "
           "of the Cauchy loss (cauchy_scale 0 still turns it off)", atLeast(0)},
          o.tukey_scale);
  v.field({"starts", "",
           "celc_opt: starts from celc's estimate on this many random row subsets (1 = celc's own); several are "
           "screened, the lowest cost refined", within(1, 64)},
          o.starts);
  v.field({"screen_events", "events", "... each start screened on this many events (0 = max_events)", atLeast(0)},
          o.screen_events);
}

void describe(FieldVisitor& v, NptOptions& o) {
  v.field({"min_line_events", "events", "a line needs this many events (>= 5)", atLeast(5)}, o.min_line_events);
  v.field({"min_lines", "", "fewer lines with a partial velocity -> degenerate", atLeast(2)}, o.min_lines);
  v.field({"min_line_sigma_ratio", "-", "a line's system without a unique nullspace is dropped", withinBelow(0, 1)},
          o.min_line_sigma_ratio);
  v.field({"max_sigma_ratio", "-", "averaging: sigma_min / sigma_second above this -> degenerate", withinAbove(0, 1)},
          o.max_sigma_ratio);
  v.enumeration({"time_origin", "", "time of the rows from the window's centre or first event (published)"},
                o.time_origin, {NptTimeOrigin::Centre, NptTimeOrigin::FirstEvent});
  v.enumeration({"line_normalisation", "", "a line's solution scaled to unit vector or unit moment (published)"},
                o.line_normalisation, {NptLineNormalisation::Vector, NptLineNormalisation::Moment});
}

void describe(FieldVisitor& v, MlOptions& o) {
  v.field({"second_start", "", "also start from npt's estimate where npt's model holds"}, o.second_start);
  v.field({"second_start_max_twist", "-", "... when |w| max|tau| / 2 is at most this", atLeast(0)},
          o.second_start_max_twist);
  v.field({"second_start_deg", "deg",
           "... and the celc start ends this far from it", atLeast(0)},
          o.second_start_deg);
  v.field({"grid_starts", "", "extra starts on a hemisphere lattice, lowest cost kept (0 = off)", within(0, 10000)},
          o.grid_starts);
  v.field({"max_events", "events",
           "events of the joint problem, a seeded subset (0 = all)", atLeast(0)},
          o.max_events);
  v.field({"screen_events", "events",
           "with several starts, each refined on about this many events (0 = all)", atLeast(0)},
          o.screen_events);
  v.field({"profile_lattice", "",
           "start from the line profile's minima: lattice directions (0 = off)", within(0, 100000)},
          o.profile_lattice);
  v.field({"profile_starts", "", "... its lowest minima refined", within(1, 100)}, o.profile_starts);
  v.field({"profile_events", "events",
           "... events per cluster in the profile (0 = all)", atLeast(0)},
          o.profile_events);
  v.field({"start_iterations", "",
           "with several starts: iterations of each before the best continues (0 = all)", atLeast(0)},
          o.start_iterations);
  v.field({"finalists", "",
           "... then this many lowest end points refined to convergence, the lowest cost kept", within(1, 100)},
          o.finalists);
  v.field({"cheiral_tie", "-",
           "end points within this of the lowest robust cost, N (C - C_min) / C_min, are tied: the one whose "
           "clusters agree best on the cheirality sign wins (0 = lowest cost)", atLeast(0)},
          o.cheiral_tie);
  v.field({"cheiral_min", "-",
           "an answer whose clusters' cheirality votes agree less than this (|sign margin|, 1 = unanimous) is "
           "replaced by the lowest-cost screened end point that reaches it, if within cheiral_clusters (0 = off)",
           within(0, 1)},
          o.cheiral_min);
  v.field({"cheiral_clusters", "-",
           "... that end point's cost within this many clusters' share of the lowest, K (C - C_min) / C_min",
           atLeast(0)},
          o.cheiral_clusters);
  v.field({"huber_scale", "-", "Huber threshold at this times the residuals' robust scale, at least "
                                "refine.huber_px (0 = off)", atLeast(0)},
          o.huber_scale);
  describeCauchyStage(v,
                      "then a last refinement under a Cauchy loss at this times the residuals' robust scale: "
                      "other edges' events in a cluster stop pulling (0 = off)",
                      o.cauchy_scale, o.cauchy_min_tail);
  v.field({"tukey_scale", "-",
           "> 0: that last refinement uses Tukey's biweight at this times the robust scale instead of the "
           "Cauchy loss (cauchy_scale 0 still turns it off)", atLeast(0)},
          o.tukey_scale);
  v.field({"cluster_test", "-",
           "> 0: then the cluster that disagrees most with the others (leaving it out moves v by more than this "
           "chi-square value allows, up to 2 degrees of freedom) is left out and v refined again, one at a time, "
           "at most a tenth of the clusters, while the answer stays in front of the camera (0 = off)",
           atLeast(0)},
          o.cluster_test);
  v.field({"rate_offset", "", "also estimate a constant gyro-rate offset with v, kept where a likelihood-ratio test "
                              "(p = 0.001) finds one (30-60 joint refinements more)"},
          o.rate_offset);
}

void describe(FieldVisitor& v, AccOptions& o) {
  v.field({"min_lines", "lines",
           "fewer usable lines: the acceleration is not observable (celc_ml's answer)", within(2, 1000)},
          o.min_lines);
  v.field({"max_sigma", "-",
           "the acceleration is observable when its std (over the speed) times the window's longest |t - t_ref| "
           "is at most this", above(0)},
          o.max_sigma);
  v.field({"test_chi2", "-",
           "the acceleration is seen when 2 (C_0 - C_a) / s^2 exceeds this (chi-square, 3 dof: 16.27 at p = 0.001); "
           "else celc_ml's answer", atLeast(0)},
          o.test_chi2);
  v.field({"accelerometer_chi2", "-",
           "an accelerating answer whose direction of a the accelerometer contradicts beyond this (chi-square, "
           "2 dof: 13.82 at p = 0.001) is not kept",
           atLeast(0)},
          o.accelerometer_chi2);
  v.field({"accelerometer_start_sigma", "-",
           "the refinement also starts from a along the accelerometer's where |a_m| is this many sigma or more",
           atLeast(0)},
          o.accelerometer_start_sigma);
}

void describe(FieldVisitor& v, UncertaintyOptions& o) {
  v.field({"enabled", "", "report sigma_deg, the direction's standard deviation, per estimate"}, o.enabled);
  v.field({"agreement", "", "sigma_deg at least the angle to a celc / celc_opt / celc_ml estimate of the window that "
                            "disagrees beyond 2 sigma"},
          o.agreement);
  v.field({"linear_witness_refined", "",
           "with agreement: a linear estimate (celc, the witness_rows subset) also raises celc_opt's and celc_ml's "
           "sigma_deg (off: only celc_opt and celc_ml witness for each other)"},
          o.linear_witness_refined);
  v.field({"witness_rows", "rows",
           "with agreement: one more witness, celc on a second random subset of this many rows (0 = none)",
           atLeast(0)},
          o.witness_rows);
  v.field({"cheiral_min", "-",
           "a celc / celc_opt / celc_ml estimate whose clusters' cheirality votes agree less than this (|sign "
           "margin|, 1 = unanimous) gets sigma_deg >= 61.2 deg (0 = off)", within(0, 1)},
          o.cheiral_min);
  v.field({"max_events", "events", "events per window used for it (0 = all)", atLeast(0)}, o.max_events);
  v.field({"scale_celc", "-", "calibration factor of sigma_deg for celc", atLeast(0)}, o.scale_celc);
  v.field({"scale_celc_opt", "-", "... for celc_opt", atLeast(0)}, o.scale_celc_opt);
  v.field({"scale_celc_ml", "-", "... for celc_ml", atLeast(0)}, o.scale_celc_ml);
  v.field({"scale_ce3lc", "-", "... for ce3lc", atLeast(0)}, o.scale_ce3lc);
  v.field({"scale_npt", "-", "... for npt", atLeast(0)}, o.scale_npt);
  v.field({"gyro_bias_rad_s", "rad/s",
           "budget: 1-sigma gyroscope bias per axis, propagated to sigma_deg (0 = left out; docs/accuracy.md)",
           within(0, 1)},
          o.gyro_bias_rad_s);
  v.field({"gyro_scale", "-", "budget: 1-sigma gyroscope scale error per axis", within(0, 0.5)}, o.gyro_scale);
  v.field({"imu_rotation_deg", "deg", "budget: 1-sigma IMU-camera rotation error about each axis", within(0, 30)},
          o.imu_rotation_deg);
  v.field({"principal_point_px", "px", "budget: 1-sigma principal point error per image axis", within(0, 100)},
          o.principal_point_px);
  v.field({"focal_share", "-", "budget: 1-sigma relative focal length error", within(0, 0.5)}, o.focal_share);
}

void describe(FieldVisitor& v, SolverOptions& o) {
  v.section({"linear", "", "robust linear stage (CELC, CE3LC)"}, [&](FieldVisitor& s) { describe(s, o.linear); });
  v.section({"refine", "", "Ceres refinement (celc_opt, celc_ml)"}, [&](FieldVisitor& s) { describe(s, o.refine); });
  v.section({"npt", "", "N-point linear solver (Gao et al. 2024)"}, [&](FieldVisitor& s) { describe(s, o.npt); });
  v.section({"ml", "", "celc_ml: joint refinement of v and the lines"}, [&](FieldVisitor& s) { describe(s, o.ml); });
  v.section({"acc", "", "celc_acc: v, a constant acceleration and the lines, jointly"},
            [&](FieldVisitor& s) { describe(s, o.acc); });
  v.section({"uncertainty", "", "sigma_deg per estimate (Fisher information at the estimate and a model-error budget)"},
            [&](FieldVisitor& s) { describe(s, o.uncertainty); });
  v.field({"check_parallax", "", "degenerate (no parallax) windows are detected once per window"},
          o.check_parallax);
}

}  // namespace celc
