// `celc batch`: many sequences, then the tables in the paper's layout.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>

#include "celc/core/memory.hpp"
#include "celc/pipeline/batch.hpp"
#include "celc/eval/run_tables.hpp"
#include "celc/io/labelled_events.hpp"
#include "commands.hpp"
#include "plots.hpp"
#include "progress.hpp"
#include "run_common.hpp"

namespace fs = std::filesystem;

namespace celc::app {
namespace {

struct BatchArgs {
  RunOverrides o;
  std::string batch, outdir = "celc_batch";
};

void runBatch(const BatchArgs& a) {
  configureLogging(a.o.quiet, a.o.verbose);
  useOneMallocArena();  // windows of megabytes: the heap in huge pages for every thread
  RunOverrides o = a.o;
  // The base: -c FILE, else the batch file's `config:`, then the command line's options.
  const BatchSpec spec = readBatch(a.batch, [&](const std::string& base_config) {
    RunOverrides base = o;
    if (base.config.empty()) base.config = base_config;
    return buildRunConfig(base);
  });
  const std::vector<BatchEntry>& entries = spec.entries;
  int shard_index = 0, shard_count = 1;
  if (!o.shard.empty()) std::tie(shard_index, shard_count) = parseShard(o.shard);
  // Check every entry's configuration before running anything.
  std::vector<SequenceJob> jobs;
  for (const auto& e : entries) {
    SequenceJob job;
    job.inputs = e.inputs;
    job.config = e.config;
    applySets(o.sets, job.config);  // the command line wins over the batch file
    defaultContainerInputs(job.inputs, job.config.reader);
    job.config.windows.t_start = std::max(job.config.windows.t_start, e.t_start);
    job.config.windows.t_end = std::min(job.config.windows.t_end, e.t_end);
    job.outdir = (fs::path(a.outdir) / e.label).string();
    job.mode = outputMode(o);
    job.threads = o.threads;
    job.shard_index = shard_index;
    job.shard_count = shard_count;
    job.title = "celc batch: " + e.label;
    jobs.push_back(job);
  }
  std::vector<SequenceSummary> table;
  for (size_t i = 0; i < jobs.size(); ++i) {
    spdlog::info("batch {}/{}: {} ({})", i + 1, jobs.size(), entries[i].label, jobs[i].inputs.events);
    Progress progress("batch " + entries[i].label, o.quiet);
    const auto outcome = runSequence(jobs[i], [&](std::uint64_t w, std::uint64_t ev) {
      progress.update(static_cast<int>(w), -1, ev);
    });
    progress.finish();
    if (!o.quiet) printSummary(jobs[i].title, outcome);
    if (automaticPlots(o.no_plots)) plotRun(jobs[i].outdir);
    table.push_back({entries[i].label, outcome.summaries});
  }
  const fs::path out(a.outdir);
  writeFileAtomically((out / "table.md").string(), tableMarkdown(table));
  writeFileAtomically((out / "table.tex").string(), tableLatex(table));
  writeFileAtomically((out / "table.csv").string(), tableCsv(table));
  if (automaticPlots(o.no_plots)) {
    std::vector<std::string> args = {"--table", (out / "table.png").string()};
    for (size_t i = 0; i < jobs.size(); ++i) {
      args.push_back("--run");
      args.push_back(entries[i].label);
      args.push_back((fs::path(jobs[i].outdir) / "windows.csv").string());
    }
    if (const std::string error = runPlotScript("plot_run.py", args); !error.empty())
      spdlog::warn("no plot {}: {}", (out / "table.png").string(), error);
  }
  std::cout << "\nTable (mean over windows with ground truth; " << (out / "table.{md,tex,csv}").string()
            << ")\n\n" << tableMarkdown(table) << std::flush;
}

}  // namespace

void registerBatch(CLI::App& app) {
  auto a = std::make_shared<BatchArgs>();
  auto* cmd = app.add_subcommand(
      "batch",
      "Many sequences from BATCH.yaml (sequences: label, path, calib, groundtruth, imu, t_start, "
      "t_end, config overrides; see config/batch_example.yaml), each into OUTDIR/<label>/, then "
      "the paper-layout tables OUTDIR/table.md, table.tex (booktabs) and table.csv; plots per "
      "sequence (OUTDIR/<label>/velocity.png, error.png) and OUTDIR/table.png (phi per method and "
      "sequence side by side) unless --no-plots.");
  cmd->add_option("batch", a->batch, "batch YAML file")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--outdir", a->outdir, "output folder")->capture_default_str();
  addRunOptions(cmd, a->o);
  cmd->callback([a]() { runBatch(*a); });
}

}  // namespace celc::app
