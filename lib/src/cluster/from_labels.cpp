// Labelled events as a clustering result, and `celc solve`'s observations of
// them (to_observations.hpp).
#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

#include "celc/cluster/to_observations.hpp"

namespace celc {

ClusterResult clustersFromLabels(const std::vector<Event>& events, const std::vector<int>& labels) {
  if (labels.size() != events.size())
    throw std::invalid_argument("clustersFromLabels: " + std::to_string(labels.size()) + " labels for " +
                                std::to_string(events.size()) + " events");
  ClusterResult out;
  out.n_events = static_cast<int>(events.size());
  out.labels.reserve(events.size());
  std::map<int, int> index_of;  // label -> index into out.clusters
  for (std::size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    if (labels[i] < 0) {
      out.labels.push_back(-1);
      continue;
    }
    auto [it, added] = index_of.emplace(labels[i], static_cast<int>(out.clusters.size()));
    if (added) {
      ClusterStats stats;
      stats.id = labels[i];
      stats.on = e.on;
      stats.t_begin = stats.t_end = e.t;
      out.clusters.push_back(stats);
    }
    ClusterStats& c = out.clusters[static_cast<std::size_t>(it->second)];
    ++c.size;
    c.t_begin = std::min(c.t_begin, e.t);
    c.t_end = std::max(c.t_end, e.t);
    out.labels.push_back(it->second);
    ++out.n_clustered;
  }
  // Clusters in ascending label order (the order a clustering's indices
  // give, so that a window dumped by `celc run --dump-windows` is observed
  // in the run's order), the labels renumbered to match.
  std::vector<int> rank(out.clusters.size());
  {
    int r = 0;
    for (const auto& [label, index] : index_of) rank[static_cast<std::size_t>(index)] = r++;
  }
  std::vector<ClusterStats> ordered(out.clusters.size());
  for (std::size_t i = 0; i < out.clusters.size(); ++i) ordered[static_cast<std::size_t>(rank[i])] = out.clusters[i];
  out.clusters = std::move(ordered);
  for (int& l : out.labels)
    if (l >= 0) l = rank[static_cast<std::size_t>(l)];
  out.status = out.clusters.empty() ? ClusterStatus::NoClusters : ClusterStatus::Ok;
  if (!events.empty()) out.t0 = std::min_element(events.begin(), events.end(), [](const Event& a, const Event& b) {
                                  return a.t < b.t;
                                })->t;
  return out;
}

LabelledObservations observeLabelledEvents(const std::vector<Event>& events, const std::vector<int>& labels,
                                           const BearingFunction& bearing, double focal_px,
                                           const ObservationOptions& options,
                                           const std::function<MotionModel(double)>& motion_from) {
  LabelledObservations out;
  out.clusters = clustersFromLabels(events, labels);
  double t_first = out.clusters.clusters.empty() ? 0.0 : out.clusters.clusters.front().t_begin;
  for (const ClusterStats& c : out.clusters.clusters) t_first = std::min(t_first, c.t_begin);
  out.motion = motion_from(t_first);
  out.observations = toObservations(events, out.clusters, bearing, focal_px, options, &out.motion, &out.report);
  return out;
}

}  // namespace celc
