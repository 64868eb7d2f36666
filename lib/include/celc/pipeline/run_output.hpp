#pragma once
/// \file run_output.hpp
/// The output folder of a run: windows.csv (rows appended and flushed per
/// window, so an interrupted run keeps every finished window), summary.md and
/// config.yaml (written to a temporary name and renamed), and resuming.
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "celc/eval/run_tables.hpp"
#include "celc/pipeline/sequence_runner.hpp"

namespace celc {

/// The windows.csv rows of one window (one per method).
std::vector<std::string> windowsCsvLines(const WindowRecord& record);

enum class OutputMode { Create, Force, Resume };

class RunOutput {
 public:
  /// Create: the folder must not hold a run (error naming it otherwise).
  /// Force: an existing run is replaced. Resume: the existing windows.csv is
  /// kept up to its last complete window (a torn last window is dropped) and
  /// resumeAfter() says where to continue.
  RunOutput(const std::string& dir, OutputMode mode, std::size_t methods_per_window);

  /// Index of the last complete window already in windows.csv (-1: none).
  std::int64_t resumeAfter() const { return resume_after_; }
  const std::string& dir() const { return dir_; }

  /// Appends one window's rows and flushes them to the file.
  void append(const WindowRecord& record);
  /// Writes config.yaml (atomically).
  void writeConfig(const std::string& yaml) const;
  /// Rewrites summary.md from windows.csv (atomically); returns the summaries.
  std::vector<MethodSummary> writeSummary(const std::string& title,
                                                const std::vector<std::string>& notes) const;

 private:
  std::string dir_, csv_path_;
  std::ofstream csv_;
  std::int64_t resume_after_ = -1;
};

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
