// Fragments of one edge: clusters whose events lie on each other's moving line.
#include "merge_fragments.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace celc::detail {

namespace {

constexpr int kTestEvents = 48;       // events of a cluster tested against another's line
constexpr double kTimeMargin = 0.1;   // a line is used this share of its span beyond its ends
constexpr double kMinInside = 0.5;    // share of the tested events that must fall in that span
constexpr double kMaxPlaneAngle = 0.05;  // [rad] (~3 deg) between the two planes at a common time

/// A cluster's events, sampled, as reference-frame bearings with their times.
struct Sample {
  std::vector<double> t;
  std::vector<Vec3> g;     ///< R(t) f
};

/// Median pixel distance of the sample's events (those within the line's
/// time span) to the line; +inf when too few of them are in its span.
double medianDistance(const Sample& s, const MovingLine& line, double focal_px, std::vector<double>& buffer) {
  const double span = line.t3 - line.t1;
  const double lo = line.t1 - kTimeMargin * span, hi = line.t3 + kTimeMargin * span;
  buffer.clear();
  for (std::size_t j = 0; j < s.t.size(); ++j) {
    if (s.t[j] < lo || s.t[j] > hi) continue;
    buffer.push_back(line.distance(s.t[j], s.g[j]));
  }
  if (buffer.size() < kMinInside * static_cast<double>(s.t.size()) || buffer.empty())
    return std::numeric_limits<double>::infinity();
  auto mid = buffer.begin() + static_cast<std::ptrdiff_t>(buffer.size() / 2);
  std::nth_element(buffer.begin(), mid, buffer.end());
  return focal_px * *mid;
}

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

std::vector<std::vector<std::size_t>> fragmentGroups(const std::vector<ClusterObservation>& clusters,
                                                     double focal_px, const MotionModel* motion,
                                                     double merge_px) {
  const std::size_t k = clusters.size();
  std::vector<MovingLine> lines(k);
  std::vector<Sample> samples(k);
  std::vector<int> parent(k);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::size_t> with_lines;
  for (std::size_t c = 0; c < k; ++c) {
    const ClusterObservation& cl = clusters[c];
    if (!movingLine(cl, motion, lines[c])) continue;
    Sample& s = samples[c];
    const std::size_t n = cl.size(), m = std::min<std::size_t>(n, kTestEvents);
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t i = (2 * j + 1) * n / (2 * m);  // spread over the cluster's time
      s.t.push_back(cl.times[i]);
      s.g.push_back(rotationAt(motion, cl.times[i]) * cl.bearings[i]);
    }
    with_lines.push_back(c);
  }
  std::vector<double> buffer;
  const double min_cos = std::cos(kMaxPlaneAngle);
  for (std::size_t a = 0; a < with_lines.size(); ++a) {
    const std::size_t i = with_lines[a];
    for (std::size_t b = a + 1; b < with_lines.size(); ++b) {
      const std::size_t j = with_lines[b];
      if (findRoot(parent, static_cast<int>(i)) == findRoot(parent, static_cast<int>(j))) continue;
      // Cheap test first: the two planes at a common time must nearly agree.
      const double tm = 0.5 * (std::max(lines[i].t1, lines[j].t1) + std::min(lines[i].t3, lines[j].t3));
      const Vec3 ni = lines[i].at(tm).normalized(), nj = lines[j].at(tm).normalized();
      if (std::abs(ni.dot(nj)) < min_cos) continue;
      if (medianDistance(samples[j], lines[i], focal_px, buffer) > merge_px) continue;
      if (medianDistance(samples[i], lines[j], focal_px, buffer) > merge_px) continue;
      parent[findRoot(parent, static_cast<int>(j))] = findRoot(parent, static_cast<int>(i));
    }
  }
  std::vector<std::vector<std::size_t>> groups;
  std::vector<int> group_of(k, -1);
  for (std::size_t c : with_lines) {
    const int r = findRoot(parent, static_cast<int>(c));
    if (group_of[r] < 0) {
      group_of[r] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group_of[r]].push_back(c);
  }
  return groups;
}

}  // namespace celc::detail
