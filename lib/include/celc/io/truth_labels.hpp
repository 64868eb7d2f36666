#pragma once
/// \file truth_labels.hpp
/// The true edge of every event of a simulated sequence: `labels.txt` beside
/// `events.txt` (`celc synth`), one integer per line in the events' order,
/// -1 for a noise event. Used to measure clusters against the truth
/// (eval/cluster_quality.hpp) and to solve a window on its true clusters.
#include <cstddef>
#include <string>
#include <vector>

#include "celc/core/types.hpp"
#include "celc/io/event_reader.hpp"

namespace celc {

class TruthLabels {
 public:
  /// Reads the events of `events_path` with the pipeline's reader and
  /// `labels_path`, one label per event read. Throws IoError naming the file
  /// and the line when a line is not an integer, or naming both files when
  /// the counts differ (an event the reader dropped would shift every label).
  static TruthLabels read(const std::string& events_path, const std::string& labels_path,
                          const ReaderOptions& reader);

  /// The true label of each of `events` (as the reader gives them: found by
  /// time, then pixel); -1 for an event not in the file.
  std::vector<int> lookup(const std::vector<Event>& events) const;

  std::size_t size() const { return labels_.size(); }

 private:
  std::vector<Event> events_;  ///< in time order, as read
  std::vector<int> labels_;
};

}  // namespace celc
