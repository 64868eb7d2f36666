// The error table of existing runs (eval/result_table.hpp): files found in
// result folders, grouped into rows, merged and summarised.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "celc/eval/result_table.hpp"
#include "cli_util.hpp"

using namespace celc;
namespace fs = std::filesystem;

namespace {

/// A row of a windows.csv (the format with sigma_deg): window w of `method`,
/// ok with phi = eps = `phi` [rad] and sigma_deg `sigma`.
struct Row {
  int window;
  std::string method;
  double phi = 0.1, sigma = 1.0;
};

/// Writes dir/windows.csv with `rows`; returns its path.
std::string writeRun(const fs::path& dir, const std::vector<Row>& rows) {
  fs::create_directories(dir);
  const fs::path csv = dir / "windows.csv";
  std::ofstream f(csv);
  f << windowsCsvHeaderV2() << "\n";
  for (const Row& r : rows)
    f << r.window << ",0,0.1,1000,5," << r.method << ",ok,0,0,1,0,0,1," << r.phi << "," << r.phi << ",1,,"
      << r.sigma << ",2,5,0,0,0\n";
  return csv.string();
}

/// A warning callback that keeps the warnings.
struct Warnings {
  std::vector<std::string> lines;
  TableWarn callback() {
    return [this](const std::string& w) { lines.push_back(w); };
  }
};

}  // namespace

TEST(EvalResultTable, FindsTheFolderAndItsSubFolders) {
  const fs::path d = test::freshTempDir("result_find");
  writeRun(d / "top", {{0, "celc"}});
  writeRun(d / "top" / "b", {{0, "celc"}});
  writeRun(d / "top" / "a", {{0, "celc"}});
  fs::create_directories(d / "top" / "empty");
  const auto found = findResultSources((d / "top").string());
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].label, "top");
  EXPECT_EQ(found[1].label, "a");  // sub-folders in ascending order
  EXPECT_EQ(found[2].label, "b");
  EXPECT_FALSE(found[0].named);
  const auto named = findResultSources((d / "top").string(), "run");
  ASSERT_EQ(named.size(), 3u);
  EXPECT_EQ(named[0].label, "run");
  EXPECT_EQ(named[1].label, "run/a");
  EXPECT_TRUE(named[2].named);
  const auto file = findResultSources((d / "top" / "a" / "windows.csv").string());
  ASSERT_EQ(file.size(), 1u);
  EXPECT_EQ(file[0].label, "a");
  EXPECT_THROW(findResultSources((d / "missing").string()), std::runtime_error);
  EXPECT_THROW(findResultSources((d / "top" / "empty").string()), std::runtime_error);
  fs::remove_all(d);
}

TEST(EvalResultTable, ShardsOfOneRunMergeAndOtherRunsOfTheSameNameAreRenamed) {
  const fs::path d = test::freshTempDir("result_group");
  std::vector<ResultSource> sources;
  for (const char* parent : {"s1", "s2", "other"})
    sources.push_back({writeRun(d / parent / "seq", {{0, "celc"}}), "seq", false});
  // Sources 0 and 1 are shards of one run; 2 is another run.
  const SameRun same_run = [](std::size_t a, std::size_t b) { return a < 2 && b < 2; };
  Warnings warnings;
  const auto groups = groupResultSources(sources, same_run, warnings.callback());
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].label, "s1/seq");
  EXPECT_EQ(groups[0].sources.size(), 2u);
  EXPECT_EQ(groups[1].label, "other/seq");
  EXPECT_EQ(warnings.lines.size(), 2u);
  // Sources the user named alike form one row whatever their runs.
  for (auto& s : sources) s.named = true;
  const auto named = groupResultSources(sources, same_run, warnings.callback());
  ASSERT_EQ(named.size(), 1u);
  EXPECT_EQ(named[0].label, "seq");
  EXPECT_EQ(named[0].sources.size(), 3u);
  fs::remove_all(d);
}

TEST(EvalResultTable, MergeCountsARowOnceAndWarnsOfMissingRows) {
  const fs::path d = test::freshTempDir("result_merge");
  ResultGroup g{"seq", {}};
  g.sources.push_back({writeRun(d / "a", {{0, "celc"}, {0, "celc_ml"}, {1, "celc"}, {1, "celc_ml"}}), "seq", false});
  g.sources.push_back({writeRun(d / "b", {{1, "celc"}, {1, "celc_ml"}, {2, "celc"}}), "seq", false});
  Warnings warnings;
  const auto rows = mergeGroupRows(g, warnings.callback());
  EXPECT_EQ(rows.size(), 5u);
  ASSERT_EQ(warnings.lines.size(), 2u);
  EXPECT_NE(warnings.lines[0].find("2 rows already read"), std::string::npos) << warnings.lines[0];
  EXPECT_NE(warnings.lines[1].find("1 (window, method) rows missing, e.g. window 2 of celc_ml"), std::string::npos)
      << warnings.lines[1];
  fs::remove_all(d);
}

TEST(EvalResultTable, TableKeepsConfidentRowsAndOrdersTheColumnsAsAsked) {
  const fs::path d = test::freshTempDir("result_build");
  ResultGroup g{"seq", {}};
  g.sources.push_back({writeRun(d / "seq", {{0, "celc", 0.2, 2.0},
                                            {0, "celc_ml", 0.1, 8.0},
                                            {1, "celc", 0.4, 2.0},
                                            {1, "celc_ml", 0.3, 1.0},
                                            {0, "ce3lc"},
                                            {1, "ce3lc"}}),
                       "seq", false});
  Warnings warnings;
  ResultTableOptions options;
  options.max_sigma_deg = 5.0;
  options.methods = {"celc_ml", "celc", "npt"};
  const ResultTable t = buildResultTable({g}, options, warnings.callback());
  EXPECT_TRUE(warnings.lines.empty());
  ASSERT_EQ(t.kept_notes.size(), 1u);
  EXPECT_EQ(t.kept_notes[0], "- seq: 5 of 6 ok rows kept");
  ASSERT_EQ(t.sequences.size(), 1u);
  const auto& methods = t.sequences[0].methods;
  ASSERT_EQ(methods.size(), 2u);  // ce3lc left out, the order as asked
  EXPECT_EQ(methods[0].method, "celc_ml");
  EXPECT_EQ(methods[0].ok, 1);  // window 0's sigma_deg is above the threshold
  EXPECT_NEAR(methods[0].phi_mean, 0.3, 1e-12);
  EXPECT_EQ(methods[1].method, "celc");
  EXPECT_NEAR(methods[1].phi_mean, 0.3, 1e-12);
  EXPECT_EQ(t.absent_methods, std::vector<std::string>{"npt"});
  fs::remove_all(d);
}
