// The error table of existing runs: files found, grouped into rows, merged
// and summarised (result_table.hpp).
#include "celc/eval/result_table.hpp"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <utility>

namespace fs = std::filesystem;

namespace celc {

namespace {

/// The name of the folder holding `csv`.
std::string folderName(const fs::path& csv) { return fs::absolute(csv).parent_path().filename().string(); }

/// How many groups carry `label`.
std::size_t labelCount(const std::vector<ResultGroup>& groups, const std::string& label) {
  return static_cast<std::size_t>(
      std::count_if(groups.begin(), groups.end(), [&label](const ResultGroup& g) { return g.label == label; }));
}

/// Renames the groups whose labels clash: after their first file's folder,
/// "parent/folder" in pass 0, its absolute path in pass 1; warns per group.
void renameClashes(std::vector<ResultGroup>& groups, int pass, const TableWarn& warn) {
  std::vector<bool> clashes;
  for (const ResultGroup& g : groups) clashes.push_back(labelCount(groups, g.label) > 1);
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (!clashes[i]) continue;
    ResultGroup& g = groups[i];
    const fs::path folder = fs::absolute(g.sources.front().csv).parent_path();
    const std::string old = g.label;
    g.label = pass == 0 ? folder.parent_path().filename().string() + "/" + folder.filename().string()
                        : folder.string();
    warn("results named '" + old + "' from different runs: this one is the row '" + g.label +
         "' (name rows with --label NAME=PATH)");
  }
}

/// The first (window, method) pair of windows x methods not in `seen`.
std::pair<std::int64_t, std::string> firstMissing(const std::set<std::int64_t>& windows,
                                                  const std::set<std::string>& methods,
                                                  const std::set<std::pair<std::int64_t, std::string>>& seen) {
  for (std::int64_t w : windows)
    for (const std::string& m : methods)
      if (!seen.count({w, m})) return {w, m};
  return {};
}

/// The position of `method` among `columns` (columns.size() when absent).
std::size_t columnOf(const std::vector<std::string>& columns, const std::string& method) {
  return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), method) - columns.begin());
}

/// A group's summary: rows restricted to `columns` (all with none) and the
/// methods sorted by their column; the methods seen before the restriction
/// are added to `found`.
SequenceSummary summarizeGroup(const std::string& label, std::vector<WindowsCsvRow> rows,
                               const std::vector<std::string>& columns, std::set<std::string>& found) {
  if (!columns.empty()) {
    for (const WindowsCsvRow& r : rows) found.insert(r.method);
    rows.erase(std::remove_if(rows.begin(), rows.end(),
                              [&columns](const WindowsCsvRow& r) { return columnOf(columns, r.method) == columns.size(); }),
               rows.end());
  }
  SequenceSummary summary{label, summarize(rows)};
  std::stable_sort(summary.methods.begin(), summary.methods.end(),
                   [&columns](const MethodSummary& x, const MethodSummary& y) {
                     return columnOf(columns, x.method) < columnOf(columns, y.method);
                   });
  return summary;
}

}  // namespace

std::vector<ResultSource> findResultSources(const std::string& path, const std::string& name) {
  const fs::path p(path);
  if (!fs::exists(p)) throw std::runtime_error(path + ": no such file or directory");
  const bool named = !name.empty();
  if (fs::is_regular_file(p)) return {{p.string(), named ? name : folderName(p), named}};
  std::vector<ResultSource> out;
  if (fs::exists(p / "windows.csv"))
    out.push_back({(p / "windows.csv").string(), named ? name : folderName(p / "windows.csv"), named});
  std::vector<fs::path> sub;
  for (const auto& e : fs::directory_iterator(p))
    if (e.is_directory() && fs::exists(e.path() / "windows.csv")) sub.push_back(e.path() / "windows.csv");
  std::sort(sub.begin(), sub.end());
  for (const fs::path& csv : sub)
    out.push_back({csv.string(), named ? name + "/" + folderName(csv) : folderName(csv), named});
  if (out.empty()) throw std::runtime_error(path + ": no windows.csv in it or in its sub-folders");
  return out;
}

std::vector<ResultGroup> groupResultSources(const std::vector<ResultSource>& sources, const SameRun& same_run,
                                            const TableWarn& warn) {
  std::vector<ResultGroup> groups;
  std::vector<std::size_t> first;  // per group, the index of its first source
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const ResultSource& s = sources[i];
    std::size_t g = 0;
    while (g < groups.size() && !(groups[g].label == s.label && (s.named || same_run(first[g], i)))) ++g;
    if (g == groups.size()) {
      groups.push_back({s.label, {}});
      first.push_back(i);
    }
    groups[g].sources.push_back(s);
  }
  for (int pass = 0; pass < 2; ++pass) renameClashes(groups, pass, warn);
  return groups;
}

std::vector<WindowsCsvRow> mergeGroupRows(const ResultGroup& group, const TableWarn& warn) {
  std::vector<WindowsCsvRow> rows;
  std::set<std::pair<std::int64_t, std::string>> seen;
  for (const ResultSource& s : group.sources) {
    int dup = 0;
    for (WindowsCsvRow& r : readWindowsCsv(s.csv)) {
      if (!seen.insert({r.window, r.method}).second) {
        ++dup;
        continue;
      }
      rows.push_back(std::move(r));
    }
    if (dup)
      warn(s.csv + ": " + std::to_string(dup) + " rows already read from another file of '" + group.label +
           "' (ignored)");
  }
  std::set<std::int64_t> windows;
  std::set<std::string> methods;
  for (const auto& [w, m] : seen) windows.insert(w), methods.insert(m);
  if (const std::size_t missing = windows.size() * methods.size() - seen.size(); missing > 0) {
    const auto [w, m] = firstMissing(windows, methods, seen);
    warn("'" + group.label + "': " + std::to_string(missing) + " (window, method) rows missing, e.g. window " +
         std::to_string(w) + " of " + m +
         ": a file of this run was cut or edited, so its methods are summarised over different windows");
  }
  return rows;
}

std::string dropAboveSigma(std::vector<WindowsCsvRow>& rows, double max_sigma_deg, const std::string& label) {
  int dropped = 0, ok = 0;
  for (WindowsCsvRow& r : rows) {
    if (r.status != "ok") continue;
    ++ok;
    if (r.sigma_deg <= max_sigma_deg) continue;
    r.status = "sigma_above_max";
    r.has_v = r.has_metrics = false;
    ++dropped;
  }
  return "- " + label + ": " + std::to_string(ok - dropped) + " of " + std::to_string(ok) + " ok rows kept";
}

ResultTable buildResultTable(const std::vector<ResultGroup>& groups, const ResultTableOptions& options,
                             const TableWarn& warn) {
  ResultTable table;
  std::set<std::string> found;
  for (const ResultGroup& g : groups) {
    std::vector<WindowsCsvRow> rows = mergeGroupRows(g, warn);
    if (options.max_sigma_deg >= 0.0) table.kept_notes.push_back(dropAboveSigma(rows, options.max_sigma_deg, g.label));
    table.sequences.push_back(summarizeGroup(g.label, std::move(rows), options.methods, found));
  }
  for (const std::string& m : options.methods)
    if (!found.count(m)) table.absent_methods.push_back(m);
  return table;
}

}  // namespace celc
