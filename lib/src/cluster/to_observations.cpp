#include "celc/cluster/to_observations.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>
#include <tuple>
#include <utility>

#include "celc/core/parallel.hpp"
#include "merge_fragments.hpp"

namespace celc {

namespace {

/// Stores the fitted lines in the cluster; has_lines says whether l1 and l3 are usable.
void attachLines(ClusterObservation& obs, const ClusterLines& lines) {
  obs.has_lines = lines.ok();
  if (!obs.has_lines) return;
  obs.l1 = lines.l1.line;
  obs.l3 = lines.l3.line;
  obs.has_l2 = lines.l2.status == LineFitStatus::Ok;
  if (obs.has_l2) obs.l2 = lines.l2.line;
}

/// Joins the fragments of one edge (merge_fragments.hpp) into the group's
/// first cluster, whose lines are fitted again on the joined events; a group
/// whose joined lines cannot be fitted stays apart.
void mergeFragments(std::vector<ClusterObservation>& built, std::vector<ClusterLines>& fits,
                    std::vector<std::vector<int>>& members, double focal_px, const ObservationOptions& options,
                    const MotionModel* motion, ObservationReport& rep) {
  const auto groups = detail::fragmentGroups(built, focal_px, motion, options.merge_px);
  std::vector<bool> gone(built.size(), false);
  for (const auto& group : groups) {
    if (group.size() < 2) continue;
    ClusterObservation joined;
    const int joined_id = built[group.front()].id;
    joined.id = joined_id;
    std::vector<std::tuple<double, Vec3, int>> all;
    for (std::size_t c : group)
      for (std::size_t j = 0; j < built[c].size(); ++j)
        all.emplace_back(built[c].times[j], built[c].bearings[j], members[c][j]);
    std::stable_sort(all.begin(), all.end(),
                     [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
    std::vector<int> joined_members;
    for (const auto& [t, b, i] : all) joined.times.push_back(t), joined.bearings.push_back(b), joined_members.push_back(i);
    const ClusterLines lines = fitClusterLines(joined.times, joined.bearings, focal_px, options.lines, motion);
    if (!lines.ok()) continue;
    attachLines(joined, lines);
    built[group.front()] = std::move(joined);
    fits[group.front()] = lines;
    members[group.front()] = std::move(joined_members);
    for (std::size_t i = 1; i < group.size(); ++i) {
      gone[group[i]] = true;
      rep.merged_ids.push_back(built[group[i]].id);
      rep.merged_into.push_back(joined_id);
    }
    rep.n_merged += static_cast<int>(group.size()) - 1;
  }
  std::size_t w = 0;
  for (std::size_t c = 0; c < built.size(); ++c) {
    if (gone[c]) continue;
    if (w != c) built[w] = std::move(built[c]), fits[w] = std::move(fits[c]), members[w] = std::move(members[c]);
    ++w;
  }
  built.resize(w);
  fits.resize(w);
  members.resize(w);
}

}  // namespace

std::string ObservationOptions::validate() const { return lines.validate() + rangeProblemsOf(*this); }

WindowObservations toObservations(const std::vector<Event>& events, const ClusterResult& clusters,
                                  const BearingFunction& bearing, double focal_px,
                                  const ObservationOptions& options, const MotionModel* motion,
                                  ObservationReport* report, std::vector<std::vector<int>>* members_out,
                                  int threads) {
  WindowObservations out;
  if (members_out) members_out->clear();
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
  // Each cluster's events (sorted by time) and lines. A cluster depends on
  // its own events only: on `threads` threads the same clusters, kept in order.
  std::vector<ClusterObservation> each(k);
  std::vector<ClusterLines> each_fit(k);
  std::vector<std::vector<int>> each_used(k);
  parallelFor(k, threads, [&](std::size_t c) {
    auto& idx = members[c];
    // Usually in time order already (a window's events come so): then the
    // stable sort would leave them as they are.
    auto earlier = [&](int a, int b) { return events[a].t < events[b].t; };
    if (!std::is_sorted(idx.begin(), idx.end(), earlier)) std::stable_sort(idx.begin(), idx.end(), earlier);
    ClusterObservation& obs = each[c];
    obs.id = clusters.clusters[c].id;
    obs.times.reserve(idx.size());
    obs.bearings.reserve(idx.size());
    std::vector<int>& used = each_used[c];
    used.reserve(idx.size());
    for (int i : idx) {
      const Vec3 b = bearing(Vec2(events[i].x, events[i].y));
      if (!b.allFinite() || !std::isfinite(events[i].t)) continue;
      obs.times.push_back(events[i].t);
      obs.bearings.push_back(b);
      used.push_back(i);
    }
    std::vector<int>().swap(idx);  // the cluster's indices are in `used` now
    if (static_cast<int>(obs.size()) < options.min_events) return;
    each_fit[c] = fitClusterLines(obs.times, obs.bearings, focal_px, options.lines, motion);
    attachLines(obs, each_fit[c]);
  });
  std::vector<ClusterObservation> built;
  std::vector<ClusterLines> fits;
  std::vector<std::vector<int>> built_members;  // input event indices of each built cluster's events
  for (size_t c = 0; c < k; ++c) {
    if (static_cast<int>(each[c].size()) < options.min_events) {
      ++rep.n_too_few_events;
      continue;
    }
    built.push_back(std::move(each[c]));
    fits.push_back(std::move(each_fit[c]));
    built_members.push_back(std::move(each_used[c]));
  }
  if (options.merge_px > 0.0) mergeFragments(built, fits, built_members, focal_px, options, motion, rep);
  if (report) {
    rep.event_clusters.assign(events.size(), -1);
    for (size_t c = 0; c < built.size(); ++c)
      for (int i : built_members[c]) rep.event_clusters[static_cast<size_t>(i)] = built[c].id;
  }
  for (size_t c = 0; c < built.size(); ++c) {
    if (!built[c].has_lines) {
      // Kept for the methods that need no lines (npt).
      ++rep.n_line_fit_failed;
      rep.failed_ids.push_back(built[c].id);
      rep.failed_lines.push_back(fits[c]);
    } else {
      rep.used_ids.push_back(built[c].id);
      rep.lines.push_back(fits[c]);
    }
    out.clusters.push_back(std::move(built[c]));
  }
  rep.n_used = static_cast<int>(rep.used_ids.size());
  if (report) *report = std::move(rep);
  if (members_out) *members_out = std::move(built_members);
  return out;
}

void dropObservationEvents(WindowObservations& obs) {
  for (ClusterObservation& c : obs.clusters) {
    std::vector<double>().swap(c.times);
    std::vector<Vec3>().swap(c.bearings);
  }
}

void restoreObservationEvents(WindowObservations& obs, const std::vector<Event>& events,
                              const std::vector<std::vector<int>>& members, const BearingFunction& bearing) {
  for (std::size_t c = 0; c < obs.clusters.size() && c < members.size(); ++c) {
    ClusterObservation& o = obs.clusters[c];
    o.times.clear();
    o.bearings.clear();
    o.times.reserve(members[c].size());
    o.bearings.reserve(members[c].size());
    for (int i : members[c]) {
      const Event& e = events[static_cast<std::size_t>(i)];
      o.times.push_back(e.t);
      o.bearings.push_back(bearing(Vec2(e.x, e.y)));
    }
  }
}

}  // namespace celc
