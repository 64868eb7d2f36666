// Validation of the solver options.
#include "celc/solver/options.hpp"

#include <cmath>
#include <sstream>

namespace celc {

std::string LinearOptions::validate() const {
  // Plain appends: every linear solve validates its options.
  std::string e;
  if (max_rows < 0) e += "max_rows must be >= 0; ";
  if (max_iterations < 1) e += "max_iterations must be >= 1; ";
  if (!(huber_k > 0.0)) e += "huber_k must be > 0; ";
  if (!(tukey_k >= 0.0) || !std::isfinite(tukey_k)) e += "tukey_k must be finite and >= 0 (0 = off); ";
  if (!(tolerance > 0.0)) e += "tolerance must be > 0; ";
  if (grid_directions < 0 || grid_starts < 0 || grid_rows < 1)
    e += "grid_directions, grid_starts must be >= 0 and grid_rows >= 1; ";
  if (min_clusters < 1) e += "min_clusters must be >= 1; ";
  if (min_cluster_events < 2) e += "min_cluster_events must be >= 2; ";
  if (!(max_nullspace_sigma_deg > 0.0)) e += "max_nullspace_sigma_deg must be > 0; ";
  if (!(min_parallax_ratio >= 1.0)) e += "min_parallax_ratio must be >= 1; ";
  if (!(min_parallax_px >= 0.0)) e += "min_parallax_px must be >= 0; ";
  if (!(min_window_parallax >= 0.0)) e += "min_window_parallax must be >= 0; ";
  return e;
}

std::string RefineOptions::validate() const {
  std::ostringstream e;
  if (!(huber_px > 0.0)) e << "huber_px must be > 0; ";
  if (max_iterations < 1) e << "max_iterations must be >= 1; ";
  if (max_events < 0) e << "max_events must be >= 0; ";
  if (!(function_tolerance > 0.0)) e << "function_tolerance must be > 0; ";
  if (num_threads < 1) e << "num_threads must be >= 1; ";
  if (!(cauchy_scale >= 0.0) || !std::isfinite(cauchy_scale)) e << "cauchy_scale must be finite and >= 0; ";
  if (!(cauchy_min_tail >= 0.0 && cauchy_min_tail <= 1.0)) e << "cauchy_min_tail must be in [0, 1]; ";
  if (!(tukey_scale >= 0.0) || !std::isfinite(tukey_scale)) e << "tukey_scale must be finite and >= 0; ";
  if (starts < 1 || starts > 64) e << "starts must be in [1, 64]; ";
  if (screen_events < 0) e << "screen_events must be >= 0; ";
  return e.str();
}

std::string MlOptions::validate() const {
  std::string e;
  if (!(second_start_deg >= 0.0)) e += "second_start_deg must be >= 0; ";
  if (!(second_start_max_twist >= 0.0)) e += "second_start_max_twist must be >= 0; ";
  if (grid_starts < 0 || grid_starts > 10000) e += "grid_starts must be in [0, 10000]; ";
  if (max_events < 0) e += "max_events must be >= 0; ";
  if (screen_events < 0) e += "screen_events must be >= 0; ";
  if (profile_lattice < 0 || profile_lattice > 100000) e += "profile_lattice must be in [0, 100000]; ";
  if (profile_starts < 1 || profile_starts > 100) e += "profile_starts must be in [1, 100]; ";
  if (profile_events < 0) e += "profile_events must be >= 0; ";
  if (start_iterations < 0) e += "start_iterations must be >= 0; ";
  if (finalists < 1 || finalists > 100) e += "finalists must be in [1, 100]; ";
  if (!(cheiral_tie >= 0.0) || !std::isfinite(cheiral_tie)) e += "cheiral_tie must be finite and >= 0; ";
  if (!(cheiral_min >= 0.0 && cheiral_min <= 1.0)) e += "cheiral_min must be in [0, 1]; ";
  if (!(cheiral_clusters >= 0.0) || !std::isfinite(cheiral_clusters))
    e += "cheiral_clusters must be finite and >= 0; ";
  if (!(huber_scale >= 0.0) || !std::isfinite(huber_scale)) e += "huber_scale must be finite and >= 0; ";
  if (!(cauchy_scale >= 0.0) || !std::isfinite(cauchy_scale)) e += "cauchy_scale must be finite and >= 0; ";
  if (!(cauchy_min_tail >= 0.0 && cauchy_min_tail <= 1.0)) e += "cauchy_min_tail must be in [0, 1]; ";
  if (!(tukey_scale >= 0.0) || !std::isfinite(tukey_scale)) e += "tukey_scale must be finite and >= 0; ";
  return e;
}

std::string AccOptions::validate() const {
  std::string e;
  if (min_lines < 2 || min_lines > 1000) e += "acc.min_lines must be in [2, 1000]; ";
  if (!(max_sigma > 0.0)) e += "acc.max_sigma must be > 0; ";
  if (!(test_chi2 >= 0.0) || !std::isfinite(test_chi2)) e += "acc.test_chi2 must be finite and >= 0; ";
  return e;
}

std::string UncertaintyOptions::validate() const {
  std::string e;
  if (max_events < 0) e += "uncertainty.max_events must be >= 0; ";
  if (witness_rows < 0) e += "uncertainty.witness_rows must be >= 0; ";
  if (!(cheiral_min >= 0.0 && cheiral_min <= 1.0)) e += "uncertainty.cheiral_min must be in [0, 1]; ";
  if (witness_rows > 0 && !agreement) e += "uncertainty.witness_rows needs uncertainty.agreement: true; ";
  for (double s : {scale_celc, scale_celc_opt, scale_celc_ml, scale_ce3lc, scale_npt})
    if (!(s >= 0.0) || !std::isfinite(s)) {
      e += "uncertainty.scale_* must be finite and >= 0; ";
      break;
    }
  if (!(gyro_bias_rad_s >= 0.0 && gyro_bias_rad_s <= 1.0)) e += "uncertainty.gyro_bias_rad_s must be in [0, 1]; ";
  if (!(gyro_scale >= 0.0 && gyro_scale <= 0.5)) e += "uncertainty.gyro_scale must be in [0, 0.5]; ";
  if (!(imu_rotation_deg >= 0.0 && imu_rotation_deg <= 30.0)) e += "uncertainty.imu_rotation_deg must be in [0, 30]; ";
  if (!(principal_point_px >= 0.0 && principal_point_px <= 100.0))
    e += "uncertainty.principal_point_px must be in [0, 100]; ";
  if (!(focal_share >= 0.0 && focal_share <= 0.5)) e += "uncertainty.focal_share must be in [0, 0.5]; ";
  return e;
}

SolverOptions SolverOptions::paper() {
  SolverOptions s;
  s.linear.grid_directions = 0;
  s.linear.grid_starts = 2;
  s.linear.tukey_k = 0.0;
  s.refine.tukey_scale = 0.0;
  s.refine.starts = 1;
  s.ml.grid_starts = 0;
  s.ml.max_events = 5000;
  s.ml.screen_events = 1000;
  s.ml.finalists = 1;
  s.ml.tukey_scale = 0.0;
  s.ml.cheiral_min = 0.0;
  s.uncertainty.cheiral_min = 0.0;
  return s;
}

std::string SolverOptions::validate() const {
  return linear.validate() + refine.validate() + npt.validate() + ml.validate() + acc.validate() +
         uncertainty.validate();
}

}  // namespace celc
