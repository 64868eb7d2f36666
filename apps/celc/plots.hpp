#pragma once
// Plots made by the Python scripts in scripts/ (Debian's python3-matplotlib),
// shared by `celc run`, `celc batch`, `celc table` and `celc simulate`.
#include <string>
#include <vector>

namespace celc::app {

/// scripts/<name>: $CELC_SCRIPTS_DIR, the source tree, or ./scripts; empty when not found.
std::string findPlotScript(const std::string& name);
/// Runs scripts/<name> ARGS with /usr/bin/python3 (or $CELC_PYTHON). Returns
/// an empty string on success, else one line saying why no plot was written.
std::string runPlotScript(const std::string& name, const std::vector<std::string>& args);
/// Plots made without being asked for: not with --no-plots, nor when the
/// environment sets CELC_NO_PLOTS (non-empty, not "0"; e.g. test suites).
bool automaticPlots(bool no_plots_flag);
/// OUTDIR/velocity.png and OUTDIR/error.png of a finished run
/// (scripts/plot_run.py); a failure is a warning.
void plotRun(const std::string& outdir);

}  // namespace celc::app
