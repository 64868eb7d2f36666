#pragma once
// Options shared by `celc run` and `celc batch`: the configuration file, the
// overrides from the command line, and the console output of a finished run.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "celc/pipeline/run_output.hpp"

namespace celc::app {

struct RunOverrides {
  std::string config;              ///< -c YAML
  std::vector<std::string> sets;   ///< --set key.path=value
  std::size_t window_events = 0;
  double window_seconds = 0.0;
  std::string methods, omega, motion_model;
  int threads = 0;
  bool force = false, resume = false, quiet = false, verbose = false;
  std::string shard;
};

/// Adds the shared options to a subcommand.
void addRunOptions(CLI::App* cmd, RunOverrides& o);
/// The configuration: defaults, then -c FILE, then the flags and --set overrides.
RunConfig buildRunConfig(const RunOverrides& o);
/// Applies `--set a.b=value` style overrides (YAML values) onto a config.
void applySets(const std::vector<std::string>& sets, RunConfig& config);
OutputMode outputMode(const RunOverrides& o);
/// Prints the per-method summary table to stdout.
void printSummary(const std::string& title, const SequenceOutcome& outcome);

}  // namespace celc::app
