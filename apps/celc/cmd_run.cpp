// `celc run`: one recorded sequence cut into windows, every method per window.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>

#include "celc/core/memory.hpp"
#include "celc/io/sequence_layout.hpp"
#include "commands.hpp"
#include "plots.hpp"
#include "progress.hpp"
#include "run_common.hpp"

namespace fs = std::filesystem;

namespace celc::app {
namespace {

struct RunArgs {
  RunOverrides o;
  std::string input, outdir, calib, groundtruth, imu, dump_windows, truth_labels;
};

void runRun(const RunArgs& a) {
  configureLogging(a.o.quiet, a.o.verbose);
  useOneMallocArena();  // windows of megabytes: the heap in huge pages for every thread
  SequenceJob job;
  job.inputs = {a.input, a.calib, a.groundtruth, a.imu, a.truth_labels};
  job.config = buildRunConfig(a.o);
  defaultContainerInputs(job.inputs, job.config.reader);
  job.mode = outputMode(a.o);
  job.threads = a.o.threads;
  job.dump_windows = a.dump_windows;
  {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) job.dump_program = self.string();
  }
  if (!a.o.shard.empty()) std::tie(job.shard_index, job.shard_count) = parseShard(a.o.shard);
  const std::string name = fs::path(a.input).filename().string().empty()
                               ? fs::path(a.input).parent_path().filename().string()
                               : fs::path(a.input).stem().string();
  job.outdir = a.outdir.empty() ? "celc_run_" + name : a.outdir;
  job.title = "celc run " + name;
  spdlog::info("run: {} -> {}", a.input, job.outdir);
  Progress progress("run " + name, a.o.quiet);
  const auto outcome = runSequence(job, [&](std::uint64_t windows, std::uint64_t events) {
    progress.update(static_cast<int>(windows), -1, events);
  });
  progress.finish();
  printSummary(job.title + " (" + job.outdir + "/summary.md)", outcome);
  if (automaticPlots(a.o.no_plots)) plotRun(job.outdir);
}

}  // namespace

void registerRun(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand(
      "run",
      "Velocity per window of a recorded sequence: INPUT is an RPG/UZH-FPV directory (" +
          sequenceLayoutSummary() +
          ") or an events/aedat file with --calib "
          "(and --groundtruth), or a ROS bag / HDF5 file (camera and ground truth from the file unless "
          "--calib / --groundtruth say otherwise; topics found by type, or --topic-events/--topic-imu/--topic-pose). "
          "Writes OUTDIR/windows.csv (one row per window and method), "
          "OUTDIR/summary.md and OUTDIR/config.yaml; prints the summary; then the plots "
          "OUTDIR/velocity.png (direction per window and method, ground truth) and OUTDIR/error.png "
          "(phi per window; with ground truth only) unless --no-plots.");
  cmd->add_option("input", a->input, "sequence directory or event file")->required();
  cmd->add_option("-o,--outdir", a->outdir, "output folder (default celc_run_<name>)");
  cmd->add_option("--calib", a->calib, std::string("calibration YAML (docs/formats.md) or ") + sequence_file::kCalibText)
      ->check(CLI::ExistingFile);
  cmd->add_option("--groundtruth", a->groundtruth, "poses `t px py pz qx qy qz qw` [s, m]")
      ->check(CLI::ExistingFile);
  cmd->add_option("--imu", a->imu, "IMU text file (when not in the sequence directory)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--truth-labels", a->truth_labels,
                  "FILE|none: the true edge of every event, one integer per line in the events' order, -1 = "
                  "noise (`celc synth`'s labels.txt, used by default when the sequence directory holds one): "
                  "windows.csv then gives each window's cluster purity, completeness, coverage and celc_ml's phi "
                  "on the true clusters (oracle_phi); `none` turns it off")
      ->check(CLI::ExistingFile | CLI::IsMember({"none"}));
  cmd->add_option("--dump-windows", a->dump_windows,
                  "also write each clustered window into this folder: window_NNNNN.csv (t,x,y,cluster: `celc "
                  "solve`'s input), window_NNNNN_gyro.csv and window_NNNNN.sh, the `celc solve` command that gives "
                  "this run's answers on it");
  addRunOptions(cmd, a->o);
  cmd->callback([a]() { runRun(*a); });
}

}  // namespace celc::app
