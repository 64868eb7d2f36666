// `celc table`: the paper-layout tables from existing windows.csv files.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <utility>

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

// One windows.csv and the row label it belongs to.
struct Source {
  fs::path csv;
  std::string label;   ///< the given NAME, or the folder's name
  bool named = false;  ///< from --label
};

// windows.csv files named directly, or found in the given folder (one level
// of sub-folders too, as `celc batch` writes them, each labelled by its
// folder's name; with a NAME, "NAME/<folder>").
std::vector<Source> findCsvs(const std::string& in, const std::string& name) {
  const fs::path p(in);
  if (!fs::exists(p)) throw std::runtime_error(in + ": no such file or directory");
  auto folderName = [](const fs::path& csv) { return fs::absolute(csv).parent_path().filename().string(); };
  if (fs::is_regular_file(p)) return {{p, name.empty() ? folderName(p) : name, !name.empty()}};
  std::vector<Source> out;
  if (fs::exists(p / "windows.csv")) out.push_back({p / "windows.csv", name.empty() ? folderName(p / "windows.csv") : name, !name.empty()});
  std::vector<fs::path> sub;
  for (const auto& e : fs::directory_iterator(p))
    if (e.is_directory() && fs::exists(e.path() / "windows.csv")) sub.push_back(e.path() / "windows.csv");
  std::sort(sub.begin(), sub.end());
  for (const auto& csv : sub)
    out.push_back({csv, name.empty() ? folderName(csv) : name + "/" + folderName(csv), !name.empty()});
  if (out.empty()) throw std::runtime_error(in + ": no windows.csv in it or in its sub-folders");
  return out;
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

// Rows are grouped by label; without --label, results of the same name merge
// only when they are shards of one run (the same configuration), else each
// keeps its own row, named by its parent folder (or its path).
struct Group {
  std::string label;
  std::optional<RunConfig> config;
  std::vector<Source> sources;
};

bool sameRun(const Group& g, const Source& s, const std::optional<RunConfig>& config) {
  if (g.label != s.label) return false;
  if (s.named) return true;  // the user named them alike: one row
  return g.config && config && firstConfigDifference(*g.config, *config).empty();
}

void runTable(const TableArgs& a) {
  configureLogging(a.quiet, false);
  std::vector<Source> sources;
  for (const auto& r : a.results) {
    const auto found = findCsvs(r, "");
    sources.insert(sources.end(), found.begin(), found.end());
  }
  for (const auto& l : a.labels) {
    const auto eq = l.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == l.size())
      throw std::runtime_error("--label '" + l + "': expected NAME=PATH");
    const auto found = findCsvs(l.substr(eq + 1), l.substr(0, eq));
    sources.insert(sources.end(), found.begin(), found.end());
  }
  if (sources.empty()) throw std::runtime_error("table: give result folders, windows.csv files or --label NAME=PATH");

  // A run that has not completed is not a result.
  for (auto& s : sources) {
    std::string reason;
    if (!isIncompleteRun(s.csv.parent_path().string(), &reason)) continue;
    const std::string where = (s.csv.parent_path() / kIncompleteMarker).string();
    if (!a.allow_incomplete)
      throw std::runtime_error(where + ": incomplete run (" + reason +
                               "); finish it with `celc run --resume`, or pass --allow-incomplete");
    spdlog::warn("{}: incomplete run, shown as '{} (incomplete)'", where, s.label);
    s.label += " (incomplete)";
  }

  std::vector<Group> groups;
  for (const auto& s : sources) {
    const auto config = configOf(s.csv);
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return sameRun(x, s, config); });
    if (g == groups.end()) {
      groups.push_back({s.label, config, {}});
      g = groups.end() - 1;
    }
    g->sources.push_back(s);
  }
  // Labels shared by different runs: each named by its parent folder, else its path.
  const auto count = [&](const std::string& label) {
    return std::count_if(groups.begin(), groups.end(), [&](const Group& x) { return x.label == label; });
  };
  for (int pass = 0; pass < 2; ++pass) {  // parent/name first, the full path where that clashes too
    std::vector<bool> clashes;
    for (const auto& g : groups) clashes.push_back(count(g.label) > 1);
    for (std::size_t i = 0; i < groups.size(); ++i) {
      if (!clashes[i]) continue;
      Group& g = groups[i];
      const fs::path folder = fs::absolute(g.sources.front().csv).parent_path();
      const std::string old = g.label;
      g.label = pass == 0 ? folder.parent_path().filename().string() + "/" + folder.filename().string()
                          : folder.string();
      spdlog::warn("results named '{}' from different runs: this one is the row '{}' (name rows with --label NAME=PATH)",
                   old, g.label);
    }
  }

  // --methods: the columns, in the order given (e.g. the paper's three).
  std::vector<std::string> wanted;
  if (!a.methods.empty()) {
    try {
      for (Method m : parseMethodList(a.methods)) wanted.push_back(toString(m));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("--methods '" + a.methods + "': " + e.what());
    }
  }
  const auto column = [&](const std::string& method) {
    return static_cast<std::size_t>(std::find(wanted.begin(), wanted.end(), method) - wanted.begin());
  };
  std::set<std::string> methods_found;

  std::vector<SequenceSummary> table;
  std::vector<std::string> kept_notes;
  for (const auto& g : groups) {
    // Shards of one run merge; a (window, method) seen twice is counted once.
    std::vector<WindowsCsvRow> rows;
    std::set<std::pair<std::int64_t, std::string>> seen;
    for (const auto& s : g.sources) {
      int dup = 0;
      for (auto& r : readWindowsCsv(s.csv.string())) {
        if (!seen.insert({r.window, r.method}).second) {
          ++dup;
          continue;
        }
        rows.push_back(r);
      }
      if (dup) spdlog::warn("{}: {} rows already read from another file of '{}' (ignored)", s.csv.string(), dup, g.label);
    }
    // Every window has a row per method of the run: a missing one means a
    // file (a shard) was cut or edited, and the methods' columns would
    // summarise different windows.
    std::set<std::int64_t> windows;
    std::set<std::string> methods;
    for (const auto& [w, m] : seen) windows.insert(w), methods.insert(m);
    if (const std::size_t missing = windows.size() * methods.size() - seen.size(); missing > 0) {
      const auto first = [&]() -> std::pair<std::int64_t, std::string> {
        for (std::int64_t w : windows)
          for (const auto& m : methods)
            if (!seen.count({w, m})) return {w, m};
        return {};
      }();
      spdlog::warn("'{}': {} (window, method) rows missing, e.g. window {} of {}: a file of this run was cut or "
                   "edited, so its methods are summarised over different windows",
                   g.label, missing, first.first, first.second);
    }
    if (a.max_sigma_deg >= 0.0) {
      // Only the windows a user would keep: ok rows above the threshold (or
      // without sigma_deg, files of the first format) count as not ok.
      int dropped = 0, ok = 0;
      for (auto& r : rows) {
        if (r.status != "ok") continue;
        ++ok;
        if (r.sigma_deg <= a.max_sigma_deg) continue;
        r.status = "sigma_above_max";
        r.has_v = r.has_metrics = false;
        ++dropped;
      }
      kept_notes.push_back("- " + g.label + ": " + std::to_string(ok - dropped) + " of " + std::to_string(ok) +
                           " ok rows kept");
    }
    if (!wanted.empty()) {
      for (const auto& r : rows) methods_found.insert(r.method);
      rows.erase(std::remove_if(rows.begin(), rows.end(),
                                [&](const WindowsCsvRow& r) { return column(r.method) == wanted.size(); }),
                 rows.end());
    }
    SequenceSummary summary{g.label, summarize(rows)};
    std::stable_sort(summary.methods.begin(), summary.methods.end(),
                     [&](const MethodSummary& x, const MethodSummary& y) { return column(x.method) < column(y.method); });
    table.push_back(std::move(summary));
  }
  for (const auto& m : wanted)
    if (!methods_found.count(m))
      throw std::runtime_error("--methods: no rows of method '" + m + "' in the results");
  if (!a.output.empty()) {
    // -o DIR/prefix: DIR is made as `celc run -o` makes its folder.
    if (const fs::path dir = fs::path(a.output).parent_path(); !dir.empty()) fs::create_directories(dir);
    writeFileAtomically(a.output + ".md", tableMarkdown(table));
    writeFileAtomically(a.output + ".tex", tableLatex(table));
    writeFileAtomically(a.output + ".csv", tableCsv(table));
    spdlog::info("wrote {}.md, {}.tex, {}.csv", a.output, a.output, a.output);
  }
  std::cout << tableMarkdown(table);
  if (a.max_sigma_deg >= 0.0) {
    std::cout << "\nOver the windows with sigma_deg <= " << a.max_sigma_deg
              << " deg (rows above it, or without sigma_deg, are left out):\n";
    for (const auto& n : kept_notes) std::cout << n << "\n";
  }
  std::cout << std::flush;
  if (!a.plot.empty()) {
    // The same rows as the table: per group its label and its CSVs (shards merge).
    std::vector<std::string> args = {"--table", a.plot};
    if (a.max_sigma_deg >= 0.0) {
      args.push_back("--max-sigma");
      args.push_back(fmt::format("{}", a.max_sigma_deg));
    }
    for (const auto& g : groups) {
      args.push_back("--run");
      args.push_back(g.label);
      for (const auto& s : g.sources) args.push_back(s.csv.string());
    }
    if (const std::string error = runPlotScript("plot_run.py", args); !error.empty())
      throw std::runtime_error("--plot " + a.plot + ": " + error);
    spdlog::info("wrote {}", a.plot);
  }
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
