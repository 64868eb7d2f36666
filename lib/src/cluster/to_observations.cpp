#include "celc/cluster/to_observations.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>

namespace celc {

std::string ObservationOptions::validate() const {
  std::ostringstream err;
  err << lines.validate();
  if (min_events < 2) err << "min_events must be >= 2; ";
  return err.str();
}

WindowObservations toObservations(const std::vector<Event>& events, const ClusterResult& clusters,
                                  const BearingFunction& bearing, double focal_px,
                                  const ObservationOptions& options, const MotionModel* motion,
                                  ObservationReport* report) {
  WindowObservations out;
  out.focal_px = focal_px;
  ObservationReport rep;
  rep.n_clusters = static_cast<int>(clusters.clusters.size());
  const size_t k = clusters.clusters.size();
  if (k == 0 || clusters.labels.size() != events.size() || !bearing || !(focal_px > 0.0) ||
      !options.validate().empty()) {
    if (report) *report = rep;
    return out;
  }
  // Event indices per cluster.
  std::vector<std::vector<int>> members(k);
  for (size_t i = 0; i < events.size(); ++i) {
    const int l = clusters.labels[i];
    if (l >= 0 && static_cast<size_t>(l) < k) members[l].push_back(static_cast<int>(i));
  }
  for (size_t c = 0; c < k; ++c) {
    auto& idx = members[c];
    std::stable_sort(idx.begin(), idx.end(),
                     [&](int a, int b) { return events[a].t < events[b].t; });
    ClusterObservation obs;
    obs.id = clusters.clusters[c].id;
    obs.times.reserve(idx.size());
    obs.bearings.reserve(idx.size());
    for (int i : idx) {
      const Vec3 b = bearing(Vec2(events[i].x, events[i].y));
      if (!b.allFinite() || !std::isfinite(events[i].t)) continue;
      obs.times.push_back(events[i].t);
      obs.bearings.push_back(b);
    }
    if (static_cast<int>(obs.size()) < options.min_events) {
      ++rep.n_too_few_events;
      continue;
    }
    const ClusterLines lines = fitClusterLines(obs.times, obs.bearings, focal_px, options.lines, motion);
    if (!lines.ok()) {
      // Kept for the methods that need no lines (npt).
      ++rep.n_line_fit_failed;
      rep.failed_ids.push_back(obs.id);
      rep.failed_lines.push_back(lines);
      obs.has_lines = false;
      out.clusters.push_back(std::move(obs));
      continue;
    }
    obs.l1 = lines.l1.line;
    obs.l3 = lines.l3.line;
    obs.has_l2 = lines.l2.status == LineFitStatus::Ok;
    if (obs.has_l2) obs.l2 = lines.l2.line;
    rep.used_ids.push_back(obs.id);
    rep.lines.push_back(lines);
    out.clusters.push_back(std::move(obs));
  }
  rep.n_used = static_cast<int>(rep.used_ids.size());
  if (report) *report = rep;
  return out;
}

}  // namespace celc
