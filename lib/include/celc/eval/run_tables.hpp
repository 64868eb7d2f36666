#pragma once
/// \file run_tables.hpp
/// `windows.csv` (DESIGN.md: one row per window and method) read back, the
/// per-method summary of a run, and the error tables in the paper's layout
/// (Tables 1 and 2: per sequence the rows eps and phi, one column per method,
/// the best in bold) as Markdown, LaTeX (booktabs) and CSV.
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

/// The header of windows.csv.
std::string windowsCsvHeader();

struct WindowsCsvRow {
  std::int64_t window = 0;
  double t_start = 0.0, t_end = 0.0;
  std::int64_t n_events = 0;
  int n_clusters = 0;
  std::string method, status;
  bool has_v = false, has_gt = false, has_metrics = false;
  Vec3 v = Vec3::Zero(), gt = Vec3::Zero();
  double eps = 0.0, phi = 0.0, runtime_ms = 0.0;
};

/// Reads a windows.csv; throws std::runtime_error("FILE:LINE: ...") on a wrong
/// header, column count or number. An incomplete last line (an interrupted
/// write) is ignored when `tolerate_truncated_tail`.
std::vector<WindowsCsvRow> readWindowsCsv(const std::string& path, bool tolerate_truncated_tail = true);

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
};

/// Summaries in the order methods first appear.
std::vector<MethodSummary> summarize(const std::vector<WindowsCsvRow>& rows);

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
