#include "celc/io/truth_labels.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>

#include "celc/core/text.hpp"

namespace celc {

TruthLabels TruthLabels::read(const std::string& events_path, const std::string& labels_path,
                              const ReaderOptions& reader_options) {
  TruthLabels out;
  std::ifstream in(labels_path);
  if (!in) throw IoError(detail::printable(labels_path) + ": cannot open");
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string text = trimBlanks(line);
    if (text.empty() || text[0] == '#') continue;
    int label = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), label);
    if (ec != std::errc() || ptr != text.data() + text.size() || label < -1)
      throw IoError(detail::printable(labels_path) + ": line " + std::to_string(line_no) +
                    ": expected an edge id (an integer >= -1), got '" + detail::printable(text, 40) + "'");
    out.labels_.push_back(label);
  }
  const auto reader = openEventSource(events_path, reader_options);
  std::vector<Event> batch;
  while (reader->next(batch, std::size_t(1) << 16)) {
    out.events_.insert(out.events_.end(), batch.begin(), batch.end());
    if (out.events_.size() > out.labels_.size()) break;  // the check below reports it
  }
  if (out.events_.size() != out.labels_.size())
    throw IoError(detail::printable(labels_path) + ": " + std::to_string(out.labels_.size()) + " labels for " +
                  (out.events_.size() > out.labels_.size() ? "more than " : "") +
                  std::to_string(out.events_.size()) + " events read from " + detail::printable(events_path) +
                  ": one label per event, in the events' order");
  return out;
}

std::vector<int> TruthLabels::lookup(const std::vector<Event>& events) const {
  std::vector<int> out(events.size(), -1);
  const auto byTime = [](const Event& e, double t) { return e.t < t; };
  for (std::size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    for (auto it = std::lower_bound(events_.begin(), events_.end(), e.t, byTime); it != events_.end() && it->t == e.t;
         ++it) {
      if (it->x == e.x && it->y == e.y && it->on == e.on) {
        out[i] = labels_[static_cast<std::size_t>(it - events_.begin())];
        break;
      }
    }
  }
  return out;
}

}  // namespace celc
