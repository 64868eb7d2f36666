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
  /// --window-events / --window-seconds as typed (empty: not given), parsed
  /// by buildRunConfig so that 0, negative and non-finite values are errors.
  std::string window_events, window_seconds;
  std::string methods, omega, motion_model;
  int threads = 0;  ///< 0 = all cores; checked by checkThreads
  bool force = false, resume = false, quiet = false, verbose = false;
  bool no_plots = false;  ///< --no-plots: no velocity.png / error.png
  std::string shard;
  /// --topic-events / --topic-imu / --topic-pose (ROS bags; empty: not given).
  std::string topic_events, topic_imu, topic_pose;
};

/// Adds the shared options to a subcommand.
void addRunOptions(CLI::App* cmd, RunOverrides& o);
/// The configuration: defaults, then -c FILE, then the flags and --set overrides.
RunConfig buildRunConfig(const RunOverrides& o);
/// Applies `--set a.b=value` style overrides (YAML values) onto a config.
void applySets(const std::vector<std::string>& sets, RunConfig& config);
/// --force and --resume: Create, Force, Resume, or (both) Resume that may
/// replace a run whose stored configuration differs.
OutputMode outputMode(const RunOverrides& o);
/// The largest --threads accepted.
constexpr int kMaxThreads = 1024;
/// --threads outside [0, kMaxThreads] is an error naming the option.
void checkThreads(int threads);
/// Prints the per-method summary table to stdout.
void printSummary(const std::string& title, const SequenceOutcome& outcome);

}  // namespace celc::app
