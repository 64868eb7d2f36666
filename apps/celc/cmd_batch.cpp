// `celc batch`: many sequences, then the tables in the paper's layout.
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <iostream>

#include "celc/config/config.hpp"
#include "celc/eval/run_tables.hpp"
#include "celc/io/labelled_events.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "run_common.hpp"

namespace fs = std::filesystem;

namespace celc::app {
namespace {

struct BatchArgs {
  RunOverrides o;
  std::string batch, outdir = "celc_batch";
};

struct BatchEntry {
  std::string label;
  RunInputs inputs;
  std::string overrides;  // YAML text of the entry's `config:` map
  std::string origin;
  double t_start = -std::numeric_limits<double>::infinity();
  double t_end = std::numeric_limits<double>::infinity();
};

std::string where(const std::string& file, const YAML::Node& n) {
  return file + ":" + std::to_string(n.Mark().line + 1);
}

// Reads BATCH.yaml: `config` (base file), `sequences` (list of entries).
std::vector<BatchEntry> readBatch(const std::string& file, std::string& base_config) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(file + ": cannot open");
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(file + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax: " + e.msg);
  }
  if (!root.IsMap()) throw std::runtime_error(file + ": expected a map with 'sequences'");
  const fs::path dir = fs::path(file).parent_path();
  auto resolve = [&](const std::string& p) { return p.empty() || fs::path(p).is_absolute() ? p : (dir / p).string(); };
  for (const auto& kv : root) {
    const std::string k = kv.first.as<std::string>();
    if (k != "config" && k != "sequences")
      throw std::runtime_error(where(file, kv.first) + ": unknown key '" + k + "' (expected config, sequences)");
  }
  if (root["config"]) base_config = resolve(root["config"].as<std::string>());
  const YAML::Node seqs = root["sequences"];
  if (!seqs || !seqs.IsSequence() || seqs.size() == 0)
    throw std::runtime_error(file + ": 'sequences' must be a non-empty list");
  std::vector<BatchEntry> out;
  for (const auto& s : seqs) {
    if (!s.IsMap()) throw std::runtime_error(where(file, s) + ": a sequence must be a map");
    BatchEntry e;
    for (const auto& kv : s) {
      const std::string k = kv.first.as<std::string>();
      const YAML::Node v = kv.second;
      try {
        if (k == "label") e.label = v.as<std::string>();
        else if (k == "path") e.inputs.events = resolve(v.as<std::string>());
        else if (k == "calib") e.inputs.calib = resolve(v.as<std::string>());
        else if (k == "groundtruth") e.inputs.groundtruth = resolve(v.as<std::string>());
        else if (k == "imu") e.inputs.imu = resolve(v.as<std::string>());
        else if (k == "t_start") e.t_start = v.as<double>();
        else if (k == "t_end") e.t_end = v.as<double>();
        else if (k == "config") {
          YAML::Emitter em;
          em << v;
          e.overrides = em.c_str();
        } else
          throw std::runtime_error(where(file, kv.first) + ": unknown key '" + k +
                                   "' (expected label, path, calib, groundtruth, imu, t_start, t_end, config)");
      } catch (const YAML::Exception&) {
        throw std::runtime_error(where(file, v) + ": key '" + k + "' has the wrong type");
      }
    }
    if (e.inputs.events.empty()) throw std::runtime_error(where(file, s) + ": sequence without 'path'");
    if (e.label.empty()) e.label = fs::path(e.inputs.events).filename().string();
    for (const auto& other : out)
      if (other.label == e.label) throw std::runtime_error(where(file, s) + ": duplicate label '" + e.label + "'");
    e.origin = file + " (sequence '" + e.label + "', config)";
    out.push_back(e);
  }
  return out;
}

void runBatch(const BatchArgs& a) {
  configureLogging(a.o.quiet, a.o.verbose);
  std::string base_config;
  const auto entries = readBatch(a.batch, base_config);
  RunOverrides o = a.o;
  if (o.config.empty()) o.config = base_config;
  const RunConfig base = buildRunConfig(o);
  int shard_index = 0, shard_count = 1;
  if (!o.shard.empty()) std::tie(shard_index, shard_count) = parseShard(o.shard);
  // Check every entry's configuration before running anything.
  std::vector<SequenceJob> jobs;
  for (const auto& e : entries) {
    SequenceJob job;
    job.inputs = e.inputs;
    job.config = base;
    if (!e.overrides.empty() && e.overrides != "~") applyRunConfig(e.overrides, e.origin, job.config);
    applySets(o.sets, job.config);  // the command line wins over the batch file
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
  std::vector<eval::SequenceSummary> table;
  for (size_t i = 0; i < jobs.size(); ++i) {
    spdlog::info("batch {}/{}: {} ({})", i + 1, jobs.size(), entries[i].label, jobs[i].inputs.events);
    Progress progress("batch " + entries[i].label, o.quiet);
    const auto outcome = runSequence(jobs[i], [&](std::uint64_t w, std::uint64_t ev) {
      progress.update(static_cast<int>(w), -1, ev);
    });
    progress.finish();
    if (!o.quiet) printSummary(jobs[i].title, outcome);
    table.push_back({entries[i].label, outcome.summaries});
  }
  const fs::path out(a.outdir);
  writeFileAtomically((out / "table.md").string(), eval::tableMarkdown(table));
  writeFileAtomically((out / "table.tex").string(), eval::tableLatex(table));
  writeFileAtomically((out / "table.csv").string(), eval::tableCsv(table));
  std::cout << "\nTable (mean over windows with ground truth; " << (out / "table.{md,tex,csv}").string()
            << ")\n\n" << eval::tableMarkdown(table) << std::flush;
}

}  // namespace

void registerBatch(CLI::App& app) {
  auto a = std::make_shared<BatchArgs>();
  auto* cmd = app.add_subcommand(
      "batch",
      "Many sequences from BATCH.yaml (sequences: label, path, calib, groundtruth, imu, t_start, "
      "t_end, config overrides; see config/batch_example.yaml), each into OUTDIR/<label>/, then "
      "the paper-layout tables OUTDIR/table.md, table.tex (booktabs) and table.csv.");
  cmd->add_option("batch", a->batch, "batch YAML file")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--outdir", a->outdir, "output folder")->capture_default_str();
  addRunOptions(cmd, a->o);
  cmd->callback([a]() { runBatch(*a); });
}

}  // namespace celc::app
