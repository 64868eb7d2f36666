// `celc table`: the paper-layout tables from existing windows.csv files.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <set>

#include "celc/eval/run_tables.hpp"
#include "celc/io/labelled_events.hpp"
#include "commands.hpp"

namespace fs = std::filesystem;

namespace celc::app {
namespace {

struct TableArgs {
  std::vector<std::string> results;
  std::string output;
  bool quiet = false;
};

// windows.csv files named directly, or found in the given folders (one level
// of sub-folders too, as `celc batch` writes them).
std::vector<fs::path> findCsvs(const std::vector<std::string>& inputs) {
  std::vector<fs::path> out;
  for (const auto& in : inputs) {
    const fs::path p(in);
    if (!fs::exists(p)) throw std::runtime_error(in + ": no such file or directory");
    if (fs::is_regular_file(p)) {
      out.push_back(p);
      continue;
    }
    if (fs::exists(p / "windows.csv")) out.push_back(p / "windows.csv");
    std::vector<fs::path> sub;
    for (const auto& e : fs::directory_iterator(p))
      if (e.is_directory() && fs::exists(e.path() / "windows.csv")) sub.push_back(e.path() / "windows.csv");
    std::sort(sub.begin(), sub.end());
    out.insert(out.end(), sub.begin(), sub.end());
  }
  if (out.empty()) throw std::runtime_error("table: no windows.csv found in the given paths");
  return out;
}

void runTable(const TableArgs& a) {
  configureLogging(a.quiet, false);
  // Rows per sequence label (the folder holding windows.csv); shards of one
  // sequence merge, a (window, method) seen twice is counted once.
  std::vector<std::string> order;
  std::map<std::string, std::vector<WindowsCsvRow>> rows;
  std::map<std::string, std::set<std::pair<std::int64_t, std::string>>> seen;
  for (const auto& csv : findCsvs(a.results)) {
    const std::string label = fs::absolute(csv).parent_path().filename().string();
    if (!rows.count(label)) order.push_back(label);
    int dup = 0;
    for (auto& r : readWindowsCsv(csv.string())) {
      if (!seen[label].insert({r.window, r.method}).second) {
        ++dup;
        continue;
      }
      rows[label].push_back(r);
    }
    if (dup) spdlog::warn("{}: {} rows already read from another file of '{}' (ignored)", csv.string(), dup, label);
  }
  std::vector<SequenceSummary> table;
  for (const auto& label : order) table.push_back({label, summarize(rows[label])});
  if (!a.output.empty()) {
    writeFileAtomically(a.output + ".md", tableMarkdown(table));
    writeFileAtomically(a.output + ".tex", tableLatex(table));
    writeFileAtomically(a.output + ".csv", tableCsv(table));
    spdlog::info("wrote {}.md, {}.tex, {}.csv", a.output, a.output, a.output);
  }
  std::cout << tableMarkdown(table) << std::flush;
}

}  // namespace

void registerTable(CLI::App& app) {
  auto a = std::make_shared<TableArgs>();
  auto* cmd = app.add_subcommand(
      "table",
      "Error tables in the paper's layout (rows eps [m/s] and phi [rad] per sequence, columns the "
      "methods, best in bold) from windows.csv files or folders holding them; shards of one "
      "sequence (same folder name) are merged. Markdown on stdout; -o PREFIX also writes "
      "PREFIX.md, PREFIX.tex (booktabs) and PREFIX.csv.");
  cmd->add_option("results", a->results, "windows.csv files or result folders")->required();
  cmd->add_option("-o,--output", a->output, "write PREFIX.md, PREFIX.tex, PREFIX.csv");
  cmd->add_flag("-q,--quiet", a->quiet, "only warnings and errors on stderr");
  cmd->callback([a]() { runTable(*a); });
}

}  // namespace celc::app
