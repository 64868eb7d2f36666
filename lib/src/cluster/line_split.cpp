// Clusters cut to the events that one moving line explains (line_split.hpp).
#include "celc/cluster/line_split.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>

#include "celc/core/parallel.hpp"

namespace celc {

namespace {

constexpr int kMinIterations = 60;    // RANSAC hypotheses per part, at least
constexpr int kMaxIterations = 400;   // ... and at most (a 5-event sample all on a line with
                                      // half the events: 99% in 145)
constexpr std::size_t kScored = 320;  // events a hypothesis is scored on, at most
constexpr std::size_t kRefined = 4000;  // events the local optimisation fits, at most
constexpr double kRotationStep = 5e-5;  // [s] events this close in time share one R(t) (3 rad/s: 0.03 px at f = 200 px)
constexpr int kSample = 5;            // a moving line linear in time has 5 degrees of freedom
constexpr double kLooseFactor = 1.5;  // hypotheses (linear in time) are scored at this times the threshold
constexpr double kRefineFactors[] = {3.0, 2.0, 1.5, 1.0, 1.0};  // the local optimisation's thresholds
constexpr double kShadowFactor = 3.0;  // a part within this times the threshold of an earlier one is its residuals' tail
constexpr std::size_t kMinPartsForScale = 6;  // parts a window needs before line_scale_ratio compares them
constexpr int kRecoverMaxParts = 16;  // moving lines drawn from one group of left-out events, at most
constexpr double kRecoverWidthRatio = 2.0;  // a recovered line's median distance, at most, in window scales
// [px] the least median distance line_scale_ratio multiplies: events on whole
// pixels lie a median 0.25 px from their line (an offset uniform in +-0.5
// px), whatever the noise; an edge that barely moves gives less
constexpr double kPixelFloorPx = 0.25;

/// One event in the motion model's reference frame: g = R(t) f with
/// f = (x, y, 1), z = R(t) e_z (the optical axis at t), t its time [s].
struct LinePoint {
  Vec3 g, z;
  double t = 0.0;
};

/// n(s) = a + s b + s^2 c: linear in time for a camera translating at a
/// constant velocity in the reference frame; the quadratic term takes the
/// curvature of the path when the camera turns with a constant body-frame
/// velocity (or accelerates), a few pixels over the longest windows.
struct Line {
  Vec3 a = Vec3::UnitZ(), b = Vec3::Zero(), c = Vec3::Zero();
  double t_mid = 0.0, span = 1.0;  ///< s = (t - t_mid) / span [s]
  double s(const LinePoint& p) const { return (p.t - t_mid) / span; }
  /// Distance of the point to the line in the image of the camera at its time
  /// [normalised units]: |m^T f| / |(m_x, m_y)| with m = R^T n, i.e.
  /// |n^T g| / sqrt(|n|^2 - (n^T z)^2).
  double distance(const LinePoint& p) const {
    const double sp = s(p);
    const Vec3 n = a + sp * (b + sp * c);
    const double den2 = n.squaredNorm() - std::pow(n.dot(p.z), 2);
    if (!(den2 > 1e-18)) return std::numeric_limits<double>::infinity();
    return std::abs(n.dot(p.g)) / std::sqrt(den2);
  }
};

/// Least squares over the points `idx` of sum w_i (n(s_i)^T g_i)^2 with |a| = 1:
/// the time terms B = (b, c) eliminated, B = -M_BB^-1 M_Ba a, and a the
/// eigenvector of the Schur complement's smallest eigenvalue. `quadratic`
/// false keeps c = 0 (5 unknowns: the minimal samples). Weights w_i = 1 /
/// |(m_x, m_y)|^2 of `prior` turn the algebraic residual into the pixel
/// distance (prior null: unit weights).
bool fitLine(const std::vector<LinePoint>& pts, const std::vector<std::size_t>& idx, const Line* prior,
             bool quadratic, Line& out) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Mat36 = Eigen::Matrix<double, 3, 6>;
  Mat3 maa = Mat3::Zero();
  Mat36 mab = Mat36::Zero();
  Mat6 mbb = Mat6::Zero();
  double t_lo = std::numeric_limits<double>::infinity(), t_hi = -t_lo;
  for (std::size_t i : idx) t_lo = std::min(t_lo, pts[i].t), t_hi = std::max(t_hi, pts[i].t);
  out.t_mid = 0.5 * (t_lo + t_hi);
  out.span = std::max(t_hi - t_lo, 1e-9);
  for (std::size_t i : idx) {
    const LinePoint& p = pts[i];
    double w = 1.0;
    if (prior) {
      const double sp = prior->s(p);
      const Vec3 n = prior->a + sp * (prior->b + sp * prior->c);
      const double den2 = n.squaredNorm() - std::pow(n.dot(p.z), 2);
      if (!(den2 > 1e-18)) continue;
      w = 1.0 / den2;
    }
    const double sp = out.s(p);
    Eigen::Matrix<double, 6, 1> time_terms;
    time_terms << sp * p.g, sp * sp * p.g;
    maa += w * p.g * p.g.transpose();
    mab += w * p.g * time_terms.transpose();
    mbb += w * time_terms * time_terms.transpose();
  }
  const int nb = quadratic ? 6 : 3;
  const Eigen::MatrixXd m_bb = mbb.topLeftCorner(nb, nb);
  const Eigen::MatrixXd m_ab = mab.leftCols(nb);
  const double ridge = 1e-12 * std::max(m_bb.trace(), 1e-300);
  const Eigen::LDLT<Eigen::MatrixXd> solve_b(m_bb + ridge * Eigen::MatrixXd::Identity(nb, nb));
  const Eigen::MatrixXd k = solve_b.solve(m_ab.transpose());  // B = -k a
  const Mat3 schur = maa - m_ab * k;
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (schur + schur.transpose()));
  if (es.info() != Eigen::Success) return false;
  out.a = es.eigenvectors().col(0);
  const Eigen::VectorXd time_part = -k * out.a;
  out.b = time_part.head<3>();
  out.c = quadratic ? Vec3(time_part.tail<3>()) : Vec3::Zero();
  return out.a.allFinite() && out.b.allFinite() && out.c.allFinite();
}

/// The indices of `candidates` within `threshold` of the line.
std::vector<std::size_t> inliersOf(const std::vector<LinePoint>& pts, const std::vector<std::size_t>& candidates,
                                   const Line& line, double threshold) {
  std::vector<std::size_t> in;
  for (std::size_t i : candidates)
    if (line.distance(pts[i]) <= threshold) in.push_back(i);
  return in;
}

/// Median distance of the points `idx` to the line [normalised units].
double medianDistance(const std::vector<LinePoint>& pts, const std::vector<std::size_t>& idx, const Line& line) {
  std::vector<double> d;
  d.reserve(idx.size());
  for (std::size_t i : idx) d.push_back(line.distance(pts[i]));
  if (d.empty()) return std::numeric_limits<double>::infinity();
  auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

/// Parts of a cluster: each a list of indices into its points, and its line.
struct Parts {
  std::vector<std::vector<std::size_t>> members;
  std::vector<Line> lines;
};

/// Sequential RANSAC over moving lines on one cluster's points (sorted by
/// time); what is in no part is noise.
Parts splitCluster(const std::vector<LinePoint>& pts, double threshold, int min_size, int max_parts,
                   std::mt19937& rng) {
  Parts result;
  auto& parts = result.members;
  auto& lines = result.lines;
  std::vector<std::size_t> rest(pts.size());
  std::iota(rest.begin(), rest.end(), std::size_t{0});
  // Each draw takes at least min_size events; shadows count as draws.
  for (int draw = 0; draw < 2 * max_parts && static_cast<int>(parts.size()) < max_parts &&
                     static_cast<int>(rest.size()) >= min_size && rest.size() >= 2 * kSample;
       ++draw) {
    const std::size_t n = rest.size();
    std::vector<std::size_t> scored;
    const std::size_t stride = std::max<std::size_t>(1, n / kScored);
    for (std::size_t k = 0; k < n; k += stride) scored.push_back(rest[k]);
    Line best;
    std::size_t best_count = 0;
    std::vector<std::size_t> sample(kSample);
    int iterations = kMaxIterations;
    for (int it = 0; it < iterations; ++it) {
      for (int q = 0; q < kSample; ++q) {  // one event from each fifth of the time order
        std::uniform_int_distribution<std::size_t> pick(q * n / kSample, (q + 1) * n / kSample - 1);
        sample[q] = rest[pick(rng)];
      }
      Line line;
      if (!fitLine(pts, sample, nullptr, false, line)) continue;
      std::size_t count = 0;
      for (std::size_t i : scored) count += line.distance(pts[i]) <= kLooseFactor * threshold ? 1 : 0;
      if (count > best_count) {
        best_count = count, best = line;
        // Enough hypotheses that one sample of 5 inliers was drawn with 99%.
        const double w = static_cast<double>(count) / static_cast<double>(scored.size());
        const double p_clean = std::pow(w, kSample);
        iterations = p_clean >= 1.0 ? kMinIterations
                                    : std::clamp(static_cast<int>(std::ceil(std::log(0.01) / std::log1p(-p_clean))),
                                                 kMinIterations, kMaxIterations);
      }
    }
    if (best_count == 0) break;
    // Local optimisation: the quadratic line fitted to the inliers of the
    // current line at a threshold that shrinks to the final one (a minimal
    // sample's line can be a few pixels off at the ends of the window).
    std::vector<std::size_t> refined;  // the local optimisation's points
    const std::size_t refine_stride = std::max<std::size_t>(1, n / kRefined);
    for (std::size_t k = 0; k < n; k += refine_stride) refined.push_back(rest[k]);
    for (double factor : kRefineFactors) {
      const std::vector<std::size_t> near = inliersOf(pts, refined, best, factor * threshold);
      Line fitted;
      if (near.size() < 3 * kSample || !fitLine(pts, near, &best, true, fitted)) break;
      best = fitted;
    }
    std::vector<std::size_t> in = inliersOf(pts, rest, best, threshold);
    if (static_cast<int>(in.size()) < min_size) break;
    std::vector<std::size_t> left;
    left.reserve(n - in.size());
    std::set_difference(rest.begin(), rest.end(), in.begin(), in.end(), std::back_inserter(left));
    rest.swap(left);
    // The tails of an earlier line's residuals, on both its sides, fit a line
    // parallel to it just beyond the threshold: such a shadow is noise.
    const bool shadow = std::any_of(lines.begin(), lines.end(), [&](const Line& earlier) {
      return medianDistance(pts, in, earlier) < kShadowFactor * threshold;
    });
    if (shadow) continue;
    parts.push_back(std::move(in));
    lines.push_back(best);
  }
  return result;
}


/// A part of a cluster after the split: its events (input indices).
struct Part {
  ClusterStats stats;
  std::vector<int> events;
  double median_px = 0.0;  ///< median distance of its events to its moving line [px]
};

/// The parts of `all` whose median distance to their line exceeds `ratio`
/// times the window's: the event-weighted median of the parts' medians (most
/// of the window's events lie on single edges), at least kPixelFloorPx, when
/// there are at least kMinPartsForScale parts.
std::vector<bool> widerThanTheWindow(const std::vector<Part>& all, double ratio) {
  std::vector<bool> wide(all.size(), false);
  if (!(ratio > 0.0) || all.size() < kMinPartsForScale) return wide;
  std::vector<std::pair<double, std::size_t>> m;  // (median, events)
  m.reserve(all.size());
  std::size_t total = 0;
  for (const Part& p : all) m.emplace_back(p.median_px, p.events.size()), total += p.events.size();
  std::sort(m.begin(), m.end());
  std::size_t below = 0;
  double window_px = m.back().first;
  for (const auto& [median, n] : m)
    if ((below += n) * 2 >= total) {
      window_px = median;
      break;
    }
  const double limit = ratio * std::max(window_px, kPixelFloorPx);
  for (std::size_t q = 0; q < all.size(); ++q) wide[q] = all[q].median_px > limit;
  return wide;
}

/// `idx` (event indices in time order) as points in the reference frame;
/// `source` gets each point's event (events without a finite bearing are skipped).
void toLinePoints(const std::vector<Event>& events, const std::vector<int>& idx, const BearingFunction& bearing,
                  const MotionModel* motion, std::vector<LinePoint>& pts, std::vector<int>& source) {
  pts.reserve(idx.size());
  source.reserve(idx.size());
  Mat3 r = Mat3::Identity();  // R(r_time); the events are in time order
  double r_time = std::numeric_limits<double>::quiet_NaN();
  for (int i : idx) {
    const Event& e = events[static_cast<std::size_t>(i)];
    const Vec3 f = bearing(Vec2(e.x, e.y));
    if (!f.allFinite() || !(std::abs(f.z()) > 0.0)) continue;
    if (motion && !(std::abs(e.t - r_time) <= kRotationStep)) r = motion->rotation(e.t), r_time = e.t;
    pts.push_back({r * (f / f.z()), r.col(2), e.t});
    source.push_back(i);
  }
}

/// The events in no part (`in_part` 0; left out for a reason other than
/// Invalid) in groups connected on a grid of options.recover_cell_px cells in
/// (x, y, c t) (26 neighbours), one polarity per group when
/// options.separate_polarity; each group in time order, groups of fewer than
/// min_cluster_size events dropped.
std::vector<std::vector<int>> leftOutGroups(const std::vector<Event>& events, const std::vector<char>& in_part,
                                            const ClusterResult& clusters, const ClusterOptions& options) {
  const double cell = options.recover_cell_px;
  const double c = clusters.c_px_per_s > 0.0 ? clusters.c_px_per_s : options.c_min_px_per_s;
  // Cell key: (c t / cell, x / cell, y / cell, polarity) packed as 37 + 13 + 13 + 1 bits.
  constexpr std::uint64_t kXY = 8192;  // cells per image axis at most (4096 px at cell >= 1 px)
  constexpr std::uint64_t kMaxT = std::uint64_t{1} << 36;
  auto cellKey = [](std::uint64_t ct, std::uint64_t cx, std::uint64_t cy, std::uint64_t pol) {
    return ((ct * kXY + cx) * kXY + cy) * 2 + pol;
  };
  std::vector<std::pair<std::uint64_t, int>> keyed;  // (cell, event)
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (in_part[i] || clusters.loss[i] == LossReason::Invalid || clusters.loss[i] == LossReason::None) continue;
    const Event& e = events[i];
    const double ct = std::floor(c * (e.t - clusters.t0) / cell);
    if (!(ct >= 0.0 && ct < static_cast<double>(kMaxT))) continue;
    const auto cx = static_cast<std::uint64_t>(e.x / cell), cy = static_cast<std::uint64_t>(e.y / cell);
    const std::uint64_t pol = options.separate_polarity && e.on ? 1 : 0;
    keyed.emplace_back(cellKey(static_cast<std::uint64_t>(ct), cx, cy, pol), static_cast<int>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  // Cells (runs of one key) joined with their 26 neighbours by union-find.
  std::vector<std::uint64_t> keys;
  std::vector<std::size_t> first;  // each cell's first entry in `keyed`
  for (std::size_t q = 0; q < keyed.size(); ++q)
    if (q == 0 || keyed[q].first != keyed[q - 1].first) keys.push_back(keyed[q].first), first.push_back(q);
  first.push_back(keyed.size());
  std::vector<std::size_t> parent(keys.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto find = [&](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const std::uint64_t pol = keys[k] % 2, cy = keys[k] / 2 % kXY, cx = keys[k] / 2 / kXY % kXY,
                        ct = keys[k] / 2 / kXY / kXY;
    for (int dt = 0; dt <= 1; ++dt)  // later cells only: each pair once
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          if (dt == 0 && (dx < 0 || (dx == 0 && dy <= 0))) continue;
          if ((dx < 0 && cx == 0) || (dy < 0 && cy == 0) || (dx > 0 && cx + 1 >= kXY) || (dy > 0 && cy + 1 >= kXY))
            continue;
          const std::uint64_t n = cellKey(ct + static_cast<std::uint64_t>(dt), cx + dx, cy + dy, pol);
          const auto it = std::lower_bound(keys.begin(), keys.end(), n);
          if (it == keys.end() || *it != n) continue;
          const std::size_t a = find(k), b = find(static_cast<std::size_t>(it - keys.begin()));
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of(keys.size(), -1);
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const std::size_t root = find(k);
    if (group_of[root] < 0) group_of[root] = static_cast<int>(groups.size()), groups.emplace_back();
    for (std::size_t q = first[k]; q < first[k + 1]; ++q)
      groups[static_cast<std::size_t>(group_of[root])].push_back(keyed[q].second);
  }
  std::vector<std::vector<int>> kept;
  for (auto& g : groups) {
    if (static_cast<int>(g.size()) < options.min_cluster_size) continue;
    std::sort(g.begin(), g.end(), [&](int a, int b) {
      return events[static_cast<std::size_t>(a)].t < events[static_cast<std::size_t>(b)].t ||
             (events[static_cast<std::size_t>(a)].t == events[static_cast<std::size_t>(b)].t && a < b);
    });
    kept.push_back(std::move(g));
  }
  return kept;
}

/// Moving lines among the events in no part (ClusterOptions::recover_cell_px):
/// each group of leftOutGroups cut by the same sequential RANSAC (up to
/// kRecoverMaxParts lines); a line's events become a part when they are
/// min_cluster_size or more, span min_extent_px, and lie within
/// kRecoverWidthRatio times the window's scale of it (median distance; the
/// scale is the median of the existing parts' medians, at least
/// kPixelFloorPx): a band of noise events along a line spreads its distances
/// over the threshold, where an edge's lie within its noise.
std::vector<Part> recoverLeftOut(const std::vector<Event>& events, const ClusterResult& clusters,
                                 const std::vector<Part>& existing, const BearingFunction& bearing, double threshold,
                                 double focal_px, const MotionModel* motion, const ClusterOptions& options) {
  std::vector<char> in_part(events.size(), 0);
  for (const Part& p : existing)
    for (int i : p.events) in_part[static_cast<std::size_t>(i)] = 1;
  std::vector<std::vector<int>> groups = leftOutGroups(events, in_part, clusters, options);
  std::vector<double> medians;
  for (const Part& p : existing) medians.push_back(p.median_px);
  double scale_px = kPixelFloorPx;
  if (!medians.empty()) {
    auto mid = medians.begin() + static_cast<std::ptrdiff_t>(medians.size() / 2);
    std::nth_element(medians.begin(), mid, medians.end());
    scale_px = std::max(*mid, kPixelFloorPx);
  }
  const double max_median_px = kRecoverWidthRatio * scale_px;
  std::vector<std::vector<Part>> found(groups.size());
  parallelFor(groups.size(), options.threads, [&](std::size_t g) {
    std::vector<LinePoint> pts;
    std::vector<int> source;
    toLinePoints(events, groups[g], bearing, motion, pts, source);
    std::mt19937 rng(options.seed + 7919u * static_cast<unsigned>(g + 1));
    const Parts parts = splitCluster(pts, threshold, options.min_cluster_size, kRecoverMaxParts, rng);
    for (std::size_t q = 0; q < parts.members.size(); ++q) {
      Part part;
      float x0 = std::numeric_limits<float>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
      for (std::size_t j : parts.members[q]) {
        const Event& e = events[static_cast<std::size_t>(source[j])];
        part.events.push_back(source[j]);
        x0 = std::min(x0, e.x), x1 = std::max(x1, e.x), y0 = std::min(y0, e.y), y1 = std::max(y1, e.y);
      }
      if (std::max(x1 - x0, y1 - y0) < options.min_extent_px) continue;
      part.median_px = medianDistance(pts, parts.members[q], parts.lines[q]) * focal_px;
      if (part.median_px > max_median_px) continue;
      std::sort(part.events.begin(), part.events.end());
      found[g].push_back(std::move(part));
    }
  });
  std::vector<Part> recovered;
  for (auto& f : found)
    for (Part& p : f) recovered.push_back(std::move(p));
  return recovered;
}

}  // namespace

LineSplitReport splitByMovingLines(const std::vector<Event>& events, ClusterResult& clusters,
                                   const BearingFunction& bearing, double focal_px, const MotionModel* motion,
                                   const ClusterOptions& options) {
  LineSplitReport report;
  if (!(options.line_split_px > 0.0) || clusters.status != ClusterStatus::Ok || !bearing || !(focal_px > 0.0) ||
      clusters.labels.size() != events.size())
    return report;
  const std::size_t k = clusters.clusters.size();
  std::vector<std::vector<int>> members(k);
  for (std::size_t i = 0; i < events.size(); ++i) {
    const int l = clusters.labels[i];
    if (l >= 0 && static_cast<std::size_t>(l) < k) members[static_cast<std::size_t>(l)].push_back(static_cast<int>(i));
  }
  const double threshold = options.line_split_px / focal_px;
  // Per cluster: its parts.
  std::vector<std::vector<Part>> parts_of(k);
  std::vector<int> removed(k, 0);
  parallelFor(k, options.threads, [&](std::size_t c) {
    std::vector<int>& idx = members[c];
    auto earlier = [&](int a, int b) { return events[a].t < events[b].t; };
    if (!std::is_sorted(idx.begin(), idx.end(), earlier)) std::stable_sort(idx.begin(), idx.end(), earlier);
    std::vector<LinePoint> pts;
    std::vector<int> source;
    toLinePoints(events, idx, bearing, motion, pts, source);
    std::mt19937 rng(options.seed + static_cast<unsigned>(c));
    const Parts parts = splitCluster(pts, threshold, options.min_cluster_size, options.max_split, rng);
    std::size_t kept = 0;
    for (std::size_t q = 0; q < parts.members.size(); ++q) {
      const auto& member = parts.members[q];
      Part part{clusters.clusters[c], {}};
      part.events.reserve(member.size());
      for (std::size_t j : member) part.events.push_back(source[j]);
      part.median_px = medianDistance(pts, member, parts.lines[q]) * focal_px;
      kept += member.size();
      parts_of[c].push_back(std::move(part));
    }
    removed[c] = static_cast<int>(idx.size() - kept);
  });
  std::vector<Part> all;
  for (std::size_t c = 0; c < k; ++c) {
    report.n_removed += removed[c];
    clusters.left_out.off_moving_lines += removed[c];
    if (parts_of[c].empty()) ++report.n_dropped;
    if (parts_of[c].size() > 1) ++report.n_split;
    for (Part& p : parts_of[c]) all.push_back(std::move(p));
  }
  // Two edges (a corner's) that one line fits within the threshold leave
  // residuals spread across it: such a part is dropped.
  const std::vector<bool> wide = widerThanTheWindow(all, options.line_scale_ratio);
  std::vector<Part> narrow;
  narrow.reserve(all.size());
  for (std::size_t q = 0; q < all.size(); ++q) {
    if (!wide[q]) {
      narrow.push_back(std::move(all[q]));
      continue;
    }
    ++report.n_wide;
    report.n_removed += static_cast<int>(all[q].events.size());
    clusters.left_out.off_moving_lines += static_cast<int>(all[q].events.size());
  }
  all.swap(narrow);
  // Where every event went: the cut's and the dropped parts' events are off the moving lines.
  const bool reasons = clusters.loss.size() == events.size();
  if (reasons) {
    std::vector<char> in_part(events.size(), 0);
    for (const Part& p : all)
      for (int i : p.events) in_part[static_cast<std::size_t>(i)] = 1;
    for (std::size_t i = 0; i < events.size(); ++i)
      if (clusters.labels[i] >= 0 && !in_part[i]) clusters.loss[i] = LossReason::OffMovingLines;
  }
  if (options.recover_cell_px > 0.0 && reasons) {
    std::vector<Part> recovered = recoverLeftOut(events, clusters, all, bearing, threshold, focal_px, motion, options);
    for (Part& p : recovered) {
      for (int i : p.events) {
        LossReason& why = clusters.loss[static_cast<std::size_t>(i)];
        ClusterLosses& l = clusters.left_out;
        int* count = why == LossReason::NoRegion         ? &l.no_region
                     : why == LossReason::SmallRegion    ? &l.small_region
                     : why == LossReason::FailedChecks   ? &l.failed_checks
                     : why == LossReason::OffPlanes      ? &l.off_planes
                     : why == LossReason::OffMovingLines ? &l.off_moving_lines
                                                         : nullptr;
        if (count) --*count;
        why = LossReason::None;
      }
      ++report.n_recovered;
      report.n_recovered_events += static_cast<int>(p.events.size());
      all.push_back(std::move(p));
    }
  }
  // New clusters: each part keeps its cluster's plane statistics.
  for (Part& p : all) {
    double t_lo = std::numeric_limits<double>::infinity(), t_hi = -t_lo;
    std::size_t n_on = 0;
    for (int i : p.events) {
      t_lo = std::min(t_lo, events[i].t), t_hi = std::max(t_hi, events[i].t);
      n_on += events[i].on ? 1 : 0;
    }
    p.stats.size = static_cast<int>(p.events.size());
    p.stats.t_begin = t_lo;
    p.stats.t_end = t_hi;
    p.stats.on = 2 * n_on >= p.events.size();
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const Part& a, const Part& b) { return a.stats.t_begin < b.stats.t_begin; });
  std::fill(clusters.labels.begin(), clusters.labels.end(), -1);
  clusters.clusters.clear();
  clusters.n_clustered = 0;
  for (Part& p : all) {
    p.stats.id = static_cast<int>(clusters.clusters.size());
    for (int i : p.events) clusters.labels[static_cast<std::size_t>(i)] = p.stats.id;
    clusters.n_clustered += p.stats.size;
    clusters.clusters.push_back(p.stats);
  }
  if (clusters.clusters.empty()) {
    clusters.status = ClusterStatus::NoClusters;
    clusters.message = "no cluster holds a moving line (cluster.line_split_px)";
  }
  return report;
}

}  // namespace celc
