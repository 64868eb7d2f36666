#pragma once
/// \file result_table.hpp
/// The error table of existing runs (`celc table`): the windows.csv files
/// found in result folders, grouped into the table's rows (the files of one
/// run, e.g. its shards, merge into one row), and each row's per-method
/// summary with the checks a merge needs (a (window, method) row read twice,
/// rows missing). Reads files and prints nothing: what a user should know is
/// handed to a warning callback.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "celc/eval/run_tables.hpp"

namespace celc {

/// One windows.csv and the row of the table it belongs to.
struct ResultSource {
  std::string csv;     ///< the windows.csv's path
  std::string label;   ///< the row's name: the given name, or the csv's folder's name
  bool named = false;  ///< the label was given by the user
};

/// Receives one warning (a line of text, no newline).
using TableWarn = std::function<void(const std::string&)>;

/// The windows.csv `path` names, or those in folder `path`: its own, then
/// those one level of sub-folders down in ascending order (as `celc batch`
/// writes them). Each is labelled by its folder's name; with a `name`, the
/// folder's own file is labelled `name` and a sub-folder's "name/<folder>".
/// Throws std::runtime_error when path does not exist or holds none.
std::vector<ResultSource> findResultSources(const std::string& path, const std::string& name = "");

/// A row of the table: its label and the files whose rows merge into it.
struct ResultGroup {
  std::string label;
  std::vector<ResultSource> sources;
};

/// Whether sources[first] and sources[other] are files of one run (e.g.
/// shards of the same configuration).
using SameRun = std::function<bool(std::size_t first, std::size_t other)>;

/// The sources as the table's rows, in order of first appearance: a source
/// joins the first group of its label when it is named (the user named them
/// alike) or when same_run(the group's first source, it) holds; otherwise it
/// opens a group. Groups whose labels still clash are renamed after their
/// first file's folder, "parent/folder", and where that clashes too, the
/// folder's absolute path; each renaming is warned about.
std::vector<ResultGroup> groupResultSources(const std::vector<ResultSource>& sources, const SameRun& same_run,
                                            const TableWarn& warn);

/// The rows of a group's files merged: a (window, method) row already read
/// from an earlier file is dropped (warned per file). Warns when the merged
/// rows miss a (window, method) pair that other rows imply (a file cut or
/// edited: the methods' columns would summarise different windows). Throws
/// std::runtime_error where a file cannot be read (readWindowsCsv).
std::vector<WindowsCsvRow> mergeGroupRows(const ResultGroup& group, const TableWarn& warn);

/// Only the windows a user would keep: the ok rows whose sigma_deg exceeds
/// max_sigma_deg [deg] (or is missing, files of the first format) become
/// status "sigma_above_max" without estimate or metrics. Returns the note
/// "- label: K of N ok rows kept".
std::string dropAboveSigma(std::vector<WindowsCsvRow>& rows, double max_sigma_deg, const std::string& label);

struct ResultTableOptions {
  double max_sigma_deg = -1.0;       ///< >= 0: dropAboveSigma at this threshold [deg]; < 0: every ok row
  std::vector<std::string> methods;  ///< the columns in this order; empty: every method of the results
};

/// The table: a sequence per group; with a sigma threshold, the note of the
/// rows kept per group; the methods asked for that no group has rows of.
struct ResultTable {
  std::vector<SequenceSummary> sequences;
  std::vector<std::string> kept_notes;
  std::vector<std::string> absent_methods;  ///< in the order of ResultTableOptions::methods
};

/// Every group's rows merged (mergeGroupRows), thresholded and restricted to
/// options.methods, summarised with the columns in that order. Throws
/// std::runtime_error where a file cannot be read.
ResultTable buildResultTable(const std::vector<ResultGroup>& groups, const ResultTableOptions& options,
                             const TableWarn& warn);

}  // namespace celc
