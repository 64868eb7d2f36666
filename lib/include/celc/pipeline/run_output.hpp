#pragma once
/// \file run_output.hpp
/// The output folder of a run: windows.csv (rows appended and flushed per
/// window, so an interrupted run keeps every finished window), summary.md and
/// config.yaml (written to a temporary name and renamed), and resuming.
///
/// A folder is a result only when it is complete: from the start of a run to
/// its end the folder holds the marker file INCOMPLETE (what stopped the run,
/// when it stopped on an error), which `celc table` refuses. A run that fails
/// before its first window removes what it created; a folder whose windows.csv
/// holds no rows is not a run (a new run needs no --force).
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "celc/eval/run_tables.hpp"
#include "celc/pipeline/sequence_runner.hpp"

namespace celc {

/// The windows.csv rows of one window (one per method).
std::vector<std::string> windowsCsvLines(const WindowRecord& record);

/// The marker of a run that has not completed (in the output folder).
inline constexpr const char* kIncompleteMarker = "INCOMPLETE";

/// True when `dir` holds the INCOMPLETE marker; `reason` gets its first line.
bool isIncompleteRun(const std::string& dir, std::string* reason = nullptr);

enum class OutputMode {
  Create,          ///< the folder must not hold a run
  Force,           ///< an existing run is replaced (its summary removed first)
  Resume,          ///< continue a run of the same configuration (refused otherwise)
  ResumeOrReplace  ///< --resume --force: continue it, or replace it when the configuration differs
};

class RunOutput {
 public:
  /// Create: the folder must not hold a run (error naming it otherwise).
  /// Force: an existing run is replaced. Resume: OUTDIR/config.yaml must hold
  /// the same configuration (result-neutral keys aside; the error names the
  /// first differing key); the existing windows.csv is kept up to its last
  /// complete window (only a torn last window is dropped) and resumeAfter()
  /// says where to continue. Writes config.yaml and the INCOMPLETE marker.
  /// `inputs`: what the rows are of (inputIdentity()), kept in input.txt;
  /// Resume also requires the same inputs (a run of another recording is
  /// not continued).
  RunOutput(const std::string& dir, OutputMode mode, const RunConfig& config, const std::string& inputs = "");

  /// Index of the last complete window already in windows.csv (-1: none).
  std::int64_t resumeAfter() const { return resume_after_; }
  const std::string& dir() const { return dir_; }
  /// Notes for the summary (a replaced run, ...).
  const std::vector<std::string>& notes() const { return notes_; }

  /// Appends one window's rows and flushes them to the file.
  void append(const WindowRecord& record);
  /// Rewrites summary.md from windows.csv (atomically); returns the summaries.
  std::vector<MethodSummary> writeSummary(const std::string& title,
                                                const std::vector<std::string>& notes) const;
  /// The run completed: removes the INCOMPLETE marker.
  void complete();
  /// The run stopped on `error`: before its first window (and with no rows
  /// kept from a resumed run) the files this run created are removed, else
  /// the marker records the error.
  void abandon(const std::string& error);

 private:
  void writeMarker(const std::string& text) const;
  std::string dir_, csv_path_;
  std::ofstream csv_;
  std::int64_t resume_after_ = -1;
  bool created_dir_ = false;
  std::size_t appended_ = 0;  ///< windows appended by this run
  std::vector<std::string> notes_;
};

/// The inputs of a run as text for input.txt: each input's absolute path (a
/// file repaired in place is still the same recording).
std::string inputIdentity(const RunInputs& inputs);

/// One sequence run into an output folder (what `celc run` and each entry of
/// `celc batch` do).
struct SequenceJob {
  RunInputs inputs;
  RunConfig config;
  std::string outdir;
  OutputMode mode = OutputMode::Create;
  int shard_index = 0, shard_count = 1;  ///< process windows with index % count == index
  int threads = 0;                       ///< 0 = all cores
  std::string title;                     ///< summary.md title
  /// Also write each clustered window for `celc solve` into this folder
  /// (pipeline/window_dump.hpp; created when missing; empty: no).
  std::string dump_windows;
  std::string dump_program = "celc";  ///< the executable the dumped commands call
};

struct SequenceOutcome {
  RunStats stats;
  std::vector<MethodSummary> summaries;
  std::vector<std::string> notes;  ///< what was opened, throughput, stage shares
};

/// Runs the job; `progress(windows, events)` as SequenceRunner::run. Throws
/// on unreadable inputs or configuration (the message names the file).
SequenceOutcome runSequence(const SequenceJob& job,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

/// "K/N" (1 <= K <= N) -> (K - 1, N); throws std::invalid_argument otherwise.
std::pair<int, int> parseShard(const std::string& text);

}  // namespace celc
