#pragma once
/// \file run_tables.hpp
/// `windows.csv` (DESIGN.md: one row per window and method) read back, the
/// per-method summary of a run, and the error tables in the paper's layout
/// (Tables 1 and 2: per sequence the rows eps and phi, one column per method,
/// the best in bold) as Markdown, LaTeX (booktabs) and CSV.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

/// The header of windows.csv: the 16 columns of the first format, then the
/// quality columns reason,sigma_deg,parallax,n_lines,wx,wy,wz,translation_px,
/// then the truth columns purity,impure_clusters,edges,edges_complete,
/// coverage,noise_admitted,oracle_phi, then sigma_deg's parts
/// sigma_fisher_deg,sigma_budget_deg,sigma_rule, then the motion model
/// columns model,ax,ay,az (docs/running.md).
std::string windowsCsvHeader();
/// The header of files written without the motion model columns (still read).
std::string windowsCsvHeaderV5();
/// The header of files written without sigma_deg's parts (still read).
std::string windowsCsvHeaderV4();
/// The header of files written without the truth columns (still read).
std::string windowsCsvHeaderV3();
/// The header of files written before translation_px (still read).
std::string windowsCsvHeaderV2();
/// The header of files written before the quality columns (still read).
std::string windowsCsvHeaderV1();
/// A row of an earlier format (16, 23, 24, 31 or 34 columns) padded with
/// empty quality, truth, sigma-part and model columns; other lines are
/// returned as they are.
std::string padWindowsCsvLine(const std::string& line);

struct WindowsCsvRow {
  std::int64_t window = 0;
  double t_start = 0.0, t_end = 0.0;
  std::int64_t n_events = 0;
  int n_clusters = 0;
  std::string method, status;
  bool has_v = false, has_gt = false, has_metrics = false;
  Vec3 v = Vec3::Zero(), gt = Vec3::Zero();
  double eps = 0.0, phi = 0.0, runtime_ms = 0.0;
  // Quality columns (empty in files of the first format).
  std::string reason;           ///< degeneracy or failure reason; empty when ok
  double sigma_deg = NAN;       ///< standard deviation of the direction [deg]; NaN: none
  double sigma_fisher_deg = NAN;  ///< its Fisher part (times the method's factor) [deg]
  double sigma_budget_deg = NAN;  ///< its model-error budget part [deg]
  std::string sigma_rule;         ///< the rule that raised it, empty when none
  /// celc_acc's choice: "acceleration" or "constant_velocity"; empty for
  /// the other methods and where it did not answer.
  std::string model;
  bool has_acceleration = false;
  /// The fitted acceleration over the speed, a / |v| [1/s], reference frame
  /// (celc_acc; also where the constant-velocity model was chosen).
  Vec3 acceleration = Vec3::Zero();
  double parallax = NAN;        ///< the window's parallax ratio [-]; NaN: none
  int n_lines = -1;             ///< usable clusters; -1: none
  bool has_omega = false;
  Vec3 omega = Vec3::Zero();    ///< angular velocity used [rad/s], camera frame
  /// The lines' translation D over the window [px] (pipeline/window_policy.hpp); NaN: none.
  double translation_px = NAN;
  /// Truth columns (runs with truth labels; eval/cluster_quality.hpp): the
  /// window's clusters against the true edges, and celc_ml's phi [rad] on
  /// its true clusters (the oracle). has_truth false: no truth.
  bool has_truth = false;
  double purity = NAN, coverage = NAN, noise_admitted = NAN, oracle_phi = NAN;
  int impure_clusters = 0, edges = 0, edges_complete = 0;
};

/// Reads a windows.csv; throws std::runtime_error("FILE:LINE: ...") on a wrong
/// header, column count or number. An incomplete last line (an interrupted
/// write) is ignored when `tolerate_truncated_tail`.
std::vector<WindowsCsvRow> readWindowsCsv(const std::string& path, bool tolerate_truncated_tail = true);

/// The clusters against the truth over a run's windows with truth columns
/// (one line each, Markdown): the median event-weighted purity, the windows
/// with at most one cluster below 95% purity, the edges with 80% of their
/// events in one cluster, the median coverage, and the windows where
/// celc_ml's phi on the pipeline's clusters is within max(1.5x, +1 deg) of
/// its phi on the true clusters (oracle_phi). Empty without truth columns.
std::string truthSummaryMarkdown(const std::vector<WindowsCsvRow>& rows);

/// The summary's default threshold on sigma_deg for the windows a user would keep [deg].
inline constexpr double kDefaultKeepSigmaDeg = 5.0;

/// Per method over a run's windows.
struct MethodSummary {
  std::string method;
  int windows = 0;     ///< rows
  int ok = 0;          ///< rows with status ok
  int with_metrics = 0;
  double eps_mean = NAN, eps_median = NAN, phi_mean = NAN, phi_median = NAN;  ///< over with_metrics
  double runtime_ms_median = NAN;
  /// Without ground truth: how consistent the directions are across windows.
  /// Mean resultant length of the sign-resolved unit estimates (1 = all equal)
  /// and the median angle to their mean direction [rad].
  double resultant_length = NAN, spread_median = NAN;
  /// The windows a user would keep: ok and sigma_deg <= max_sigma_deg.
  double max_sigma_deg = NAN;   ///< the threshold used [deg]
  int kept = 0;                 ///< ok rows with sigma_deg <= max_sigma_deg
  int kept_with_metrics = 0;
  double kept_phi_mean = NAN, kept_phi_median = NAN;   ///< [rad], over kept rows with ground truth
  double kept_resultant_length = NAN;                  ///< R over the kept rows
  std::vector<std::int64_t> kept_windows;              ///< the kept rows' window indices, ascending
};

/// Window indices as ranges, "0-3, 7, 9-10"; after `max_ranges` ranges,
/// ", ... (N windows)".
std::string windowRanges(const std::vector<std::int64_t>& windows, std::size_t max_ranges = 20);

/// Summaries in the order methods first appear.
/// With max_sigma_deg finite, the ok rows whose sigma_deg exceeds it (or
/// have none) count as not kept: `kept` and the kept_* fields describe the rest.
std::vector<MethodSummary> summarize(const std::vector<WindowsCsvRow>& rows,
                                     double max_sigma_deg = kDefaultKeepSigmaDeg);

/// summary.md of a run: per method windows ok, mean and median eps and phi.
std::string summaryMarkdown(const std::string& title, const std::vector<MethodSummary>& methods,
                            const std::vector<std::string>& notes = {});

/// One sequence of a table.
struct SequenceSummary {
  std::string label;
  std::vector<MethodSummary> methods;
};

/// Display name of a method in the tables (celc -> CELC, celc_opt -> CELC+opt, ...).
std::string methodDisplayName(const std::string& method);

/// The paper's layout: rows "label eps (unit-vector distance)" (|v_gt - v| on
/// unit vectors, no unit) and "label phi [rad]", columns
/// the methods (means over the windows with metrics), best per row in bold.
std::string tableMarkdown(const std::vector<SequenceSummary>& sequences);
std::string tableLatex(const std::vector<SequenceSummary>& sequences);
std::string tableCsv(const std::vector<SequenceSummary>& sequences);

}  // namespace celc
