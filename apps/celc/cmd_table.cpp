// `celc table`: the paper-layout tables from existing windows.csv files.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <optional>
#include <utility>

#include "celc/eval/result_table.hpp"
#include "celc/eval/run_tables.hpp"
#include "celc/io/labelled_events.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/run_output.hpp"
#include "celc/solver/methods.hpp"
#include "commands.hpp"
#include "plots.hpp"

namespace fs = std::filesystem;

namespace celc::app {
namespace {

struct TableArgs {
  std::vector<std::string> results;
  std::vector<std::string> labels;  ///< NAME=PATH
  std::string output;
  std::string plot;  ///< --plot FILE.png (empty: none)
  double max_sigma_deg = -1.0;  ///< < 0: every ok row
  std::string methods;  ///< --methods LIST (empty: every method in the results)
  bool quiet = false, allow_incomplete = false;
};

// The sources the arguments name: the result paths, then the --label NAME=PATH ones.
std::vector<ResultSource> argumentSources(const TableArgs& a) {
  std::vector<ResultSource> sources;
  for (const auto& r : a.results) {
    const auto found = findResultSources(r, "");
    sources.insert(sources.end(), found.begin(), found.end());
  }
  for (const auto& l : a.labels) {
    const auto eq = l.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == l.size())
      throw std::runtime_error("--label '" + l + "': expected NAME=PATH");
    const auto found = findResultSources(l.substr(eq + 1), l.substr(0, eq));
    sources.insert(sources.end(), found.begin(), found.end());
  }
  if (sources.empty()) throw std::runtime_error("table: give result folders, windows.csv files or --label NAME=PATH");
  return sources;
}

// A run that has not completed is not a result: refused, or with
// --allow-incomplete labelled "(incomplete)".
void markIncomplete(std::vector<ResultSource>& sources, bool allow_incomplete) {
  for (auto& s : sources) {
    const fs::path folder = fs::path(s.csv).parent_path();
    std::string reason;
    if (!isIncompleteRun(folder.string(), &reason)) continue;
    const std::string where = (folder / kIncompleteMarker).string();
    if (!allow_incomplete)
      throw std::runtime_error(where + ": incomplete run (" + reason +
                               "); finish it with `celc run --resume`, or pass --allow-incomplete");
    spdlog::warn("{}: incomplete run, shown as '{} (incomplete)'", where, s.label);
    s.label += " (incomplete)";
  }
}

// The run's configuration (config.yaml beside windows.csv), when readable.
std::optional<RunConfig> configOf(const fs::path& csv) {
  const fs::path cfg = csv.parent_path() / "config.yaml";
  if (!fs::exists(cfg)) return std::nullopt;
  try {
    return loadRunConfig(cfg.string());
  } catch (const std::exception& e) {
    spdlog::warn("{}: not compared with other runs ({})", cfg.string(), e.what());
    return std::nullopt;
  }
}

// --methods: the columns, in the order given (e.g. the paper's three); empty: every method.
std::vector<std::string> columnMethods(const std::string& list) {
  std::vector<std::string> wanted;
  if (list.empty()) return wanted;
  try {
    for (Method m : parseMethodList(list)) wanted.push_back(toString(m));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("--methods '" + list + "': " + e.what());
  }
  return wanted;
}

// -o PREFIX: PREFIX.md, .tex and .csv; its folder is made as `celc run -o` makes its own.
void writeTableFiles(const std::string& prefix, const std::vector<SequenceSummary>& table) {
  if (const fs::path dir = fs::path(prefix).parent_path(); !dir.empty()) fs::create_directories(dir);
  writeFileAtomically(prefix + ".md", tableMarkdown(table));
  writeFileAtomically(prefix + ".tex", tableLatex(table));
  writeFileAtomically(prefix + ".csv", tableCsv(table));
  spdlog::info("wrote {}.md, {}.tex, {}.csv", prefix, prefix, prefix);
}

// The table on stdout, with the rows kept per run under --max-sigma.
void printTable(const ResultTable& table, double max_sigma_deg) {
  std::cout << tableMarkdown(table.sequences);
  if (max_sigma_deg >= 0.0) {
    std::cout << "\nOver the windows with sigma_deg <= " << max_sigma_deg
              << " deg (rows above it, or without sigma_deg, are left out):\n";
    for (const auto& n : table.kept_notes) std::cout << n << "\n";
  }
  std::cout << std::flush;
}

// --plot: the same rows as the table, per group its label and its CSVs (shards merge).
void plotTable(const std::string& png, double max_sigma_deg, const std::vector<ResultGroup>& groups) {
  std::vector<std::string> args = {"--table", png};
  if (max_sigma_deg >= 0.0) {
    args.push_back("--max-sigma");
    args.push_back(fmt::format("{}", max_sigma_deg));
  }
  for (const auto& g : groups) {
    args.push_back("--run");
    args.push_back(g.label);
    for (const auto& s : g.sources) args.push_back(s.csv);
  }
  if (const std::string error = runPlotScript("plot_run.py", args); !error.empty())
    throw std::runtime_error("--plot " + png + ": " + error);
  spdlog::info("wrote {}", png);
}

// Rows are grouped by label; without --label, results of the same name merge
// only when they are shards of one run (the same configuration), else each
// keeps its own row, named by its parent folder (or its path).
void runTable(const TableArgs& a) {
  configureLogging(a.quiet, false);
  std::vector<ResultSource> sources = argumentSources(a);
  markIncomplete(sources, a.allow_incomplete);
  std::vector<std::optional<RunConfig>> configs;
  for (const auto& s : sources) configs.push_back(configOf(s.csv));
  const SameRun same_config = [&configs](std::size_t first, std::size_t other) {
    return configs[first] && configs[other] && firstConfigDifference(*configs[first], *configs[other]).empty();
  };
  const TableWarn warn = [](const std::string& message) { spdlog::warn("{}", message); };
  const std::vector<ResultGroup> groups = groupResultSources(sources, same_config, warn);
  const ResultTable table = buildResultTable(groups, {a.max_sigma_deg, columnMethods(a.methods)}, warn);
  if (!table.absent_methods.empty())
    throw std::runtime_error("--methods: no rows of method '" + table.absent_methods.front() + "' in the results");
  if (!a.output.empty()) writeTableFiles(a.output, table.sequences);
  printTable(table, a.max_sigma_deg);
  if (!a.plot.empty()) plotTable(a.plot, a.max_sigma_deg, groups);
}

}  // namespace

void registerTable(CLI::App& app) {
  auto a = std::make_shared<TableArgs>();
  auto* cmd = app.add_subcommand(
      "table",
      "Error tables in the paper's layout (rows eps, the distance between the unit estimate and "
      "the unit ground truth, and phi [rad] per sequence; columns the methods, best in bold) from "
      "windows.csv files or folders holding them. A row per run, named by its folder or by "
      "--label; shards of one run (same name, same config.yaml) merge; incomplete runs (an "
      "INCOMPLETE marker) are refused. Markdown on stdout; -o PREFIX also writes PREFIX.md, "
      "PREFIX.tex (booktabs) and PREFIX.csv.");
  cmd->add_option("results", a->results, "windows.csv files or result folders");
  cmd->add_option("--label", a->labels,
                  "NAME=PATH: the results in PATH as the row NAME (repeatable; the same NAME twice "
                  "merges, e.g. shards)");
  cmd->add_option("-o,--output", a->output, "write PREFIX.md, PREFIX.tex, PREFIX.csv");
  cmd->add_option("--plot", a->plot,
                  "FILE.png: the runs side by side, per run a box plot of phi [deg] per method and the "
                  "share of ok windows (scripts/plot_run.py, python3-matplotlib)");
  cmd->add_option("--max-sigma", a->max_sigma_deg,
                  "DEG: only the windows a user would keep, ok rows with sigma_deg <= DEG [deg] "
                  "(rows without sigma_deg, from older files, are left out)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--methods", a->methods,
                  "comma-separated methods, the table's columns in this order (default: every method in "
                  "the results); --methods celc,celc_opt,ce3lc gives the paper's three columns");
  cmd->add_flag("--allow-incomplete", a->allow_incomplete,
                "include runs that have not completed, their rows marked '(incomplete)'");
  cmd->add_flag("-q,--quiet", a->quiet, "only warnings and errors on stderr");
  cmd->callback([a]() { runTable(*a); });
}

}  // namespace celc::app
