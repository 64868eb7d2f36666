// Clusters redrawn under the window's estimated motion (motion_reassign.hpp).
#include "celc/cluster/motion_reassign.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <unordered_map>

#include "celc/core/parallel.hpp"

namespace celc {

namespace {

constexpr int kKnots = 1024;           // R(t), P(t) v tabulated at this many times, linear in between
constexpr std::size_t kFitEvents = 2000;  // events a line is fitted on, at most (evenly spread)
constexpr int kIrlsIterations = 4;
constexpr int kRansacIterations = 40;  // samples per line
constexpr int kSample = 5;             // points per sample (4 unknowns)
constexpr std::size_t kScored = 200;   // points a sample is scored on, at most
constexpr double kMinScalePx = 0.3;    // the fit's robust scale, at least [px]
constexpr double kTukey = 4.685;       // Tukey's biweight cut-off [robust scales]
constexpr double kPolarityShare = 0.1;  // a group takes a polarity that is at least this share of its events
constexpr double kToleranceScales = 2.5;  // an event is a line's within the threshold or this many of its robust scales
constexpr std::size_t kPrefilterEvents = 32;  // a pair is fitted jointly when one's line passes near these of the other's
constexpr double kPrefilterPx = 10.0;          // ... within this (median) [px]
constexpr std::size_t kJoinEvents = 400;       // events a join is tested on per group, at most
constexpr double kCellPx = 4.0;        // the neighbourhood of a cluster: cells of this size [px] ...
constexpr int kTimeBins = 20;          // ... and this many time bins per window, +-1 cell and bin
constexpr double kMadToSigma = 1.4826;

/// One event seen from the reference frame: g = R(t) f, z = R(t) e_z, c = P(t) v.
struct MotionPoint {
  Vec3 g, z, c;
};

/// R(t) and P(t) v at kKnots times over [t_lo, t_hi], linearly interpolated
/// (the rotation's error is (step angle)^2 / 8: 1e-6 rad for 2.4 rad per window).
class MotionTable {
 public:
  MotionTable(const MotionModel& motion, const Vec3& v, double t_lo, double t_hi) : t_lo_(t_lo) {
    step_ = std::max(t_hi - t_lo, 1e-9) / (kKnots - 1);
    r_.resize(kKnots);
    c_.resize(kKnots);
    for (int k = 0; k < kKnots; ++k) {
      Mat3 r, p;
      motion.pose(t_lo + k * step_, r, p);
      r_[k] = r;
      c_[k] = p * v;
    }
  }
  /// The event's point, or false when its bearing is not finite.
  bool point(const Event& e, const Vec3& f, MotionPoint& out) const {
    if (!f.allFinite() || !(std::abs(f.z()) > 0.0)) return false;
    const double s = std::clamp((e.t - t_lo_) / step_, 0.0, static_cast<double>(kKnots - 1));
    const int k = std::min(static_cast<int>(s), kKnots - 2);
    const double w = s - k;
    const Mat3 r = (1.0 - w) * r_[k] + w * r_[k + 1];
    out.g = r * (f / f.z());
    out.z = r.col(2);
    out.c = (1.0 - w) * c_[k] + w * c_[k + 1];
    return true;
  }

 private:
  double t_lo_, step_;
  std::vector<Mat3> r_;
  std::vector<Vec3> c_;
};

/// A 3D line under the motion, as its image at a time t_c and its direction:
/// the plane normal at an event's time is n_c + (c_c - c) x d, with
/// c_c = c(t_c) (the moment is m = n_c + c_c x d). |n_c| = 1 keeps the fit
/// off the line through the camera's path (m = 0, d along v), whose planes
/// hold every event and which no image shows.
struct MotionLine {
  Vec3 n_c = Vec3::UnitZ(), c_c = Vec3::Zero(), d = Vec3::Zero();
  Vec3 normal(const MotionPoint& p) const { return n_c + (c_c - p.c).cross(d); }
  /// Distance in the image at the event's time [normalised units]; `den2`,
  /// when given, receives |n|^2 - (n.z)^2 (infinite distance where it is not
  /// above 1e-18).
  double distance(const MotionPoint& p, double* den2_out = nullptr) const {
    const Vec3 n = normal(p);
    const double den2 = n.squaredNorm() - std::pow(n.dot(p.z), 2);
    if (den2_out) *den2_out = den2;
    if (!(den2 > 1e-18)) return std::numeric_limits<double>::infinity();
    return std::abs(n.dot(p.g)) / std::sqrt(den2);
  }
};

/// The normal equations of g^T n_c + (g x (c_c - c))^T d = 0, summed over
/// weighted points.
struct MotionLineSums {
  Mat3 nn = Mat3::Zero(), nd = Mat3::Zero(), dd = Mat3::Zero();
  void add(const MotionPoint& p, const Vec3& c_c, double w) {
    const Vec3 e = p.g.cross(c_c - p.c);
    nn += w * p.g * p.g.transpose();
    nd += w * p.g * e.transpose();
    dd += w * e * e.transpose();
  }
  /// n_c (|n_c| = 1) and d of the sums' least squares: d eliminated, n_c the
  /// Schur complement's smallest eigenvector. Under a translation along v
  /// alone d's component along v does not move the planes (a small ridge
  /// fixes it). False when the sums do not fix a line.
  bool solve(MotionLine& line) const {
    const double ridge = 1e-12 * std::max(dd.trace(), 1e-300);
    const Mat3 k = (dd + ridge * Mat3::Identity()).ldlt().solve(nd.transpose());  // d = -k n_c
    const Mat3 schur = nn - nd * k;
    const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (schur + schur.transpose()));
    if (es.info() != Eigen::Success) return false;
    line.n_c = es.eigenvectors().col(0);
    line.d = -k * line.n_c;
    return line.n_c.allFinite() && line.d.allFinite();
  }
};

/// Tukey's biweight over the pixel distance's variance, w = (1 - u^2)^2 /
/// den2 with u = distance / cutoff; false (no row) beyond the cutoff or
/// without a distance.
bool tukeyPlaneWeight(double distance, double den2, double cutoff, double& w) {
  if (!(den2 > 1e-18)) return false;
  const double u = distance / cutoff;
  if (!(u < 1.0)) return false;
  w = (1.0 - u * u) * (1.0 - u * u) / den2;
  return true;
}

/// Weighted least squares of g^T n_c + (g x (c_c - c))^T d = 0 over the
/// points `idx` with |n_c| = 1 (MotionLineSums::solve); `line` gives c_c,
/// and with `prior` true its current planes weight each row by
/// tukeyPlaneWeight at `cutoff` [normalised units]: the pixel distance's
/// variance times Tukey's biweight. False when the points do not fix a line.
bool solveMotionLine(const std::vector<MotionPoint>& pts, const std::vector<std::size_t>& idx, bool prior,
                     double cutoff, MotionLine& line) {
  MotionLineSums sums;
  for (std::size_t k : idx) {
    const MotionPoint& p = pts[k];
    double w = 1.0;
    if (prior) {
      double den2 = 0.0;
      const double distance = line.distance(p, &den2);
      if (!tukeyPlaneWeight(distance, den2, cutoff, w)) continue;
    }
    sums.add(p, line.c_c, w);
  }
  return sums.solve(line);
}

/// IRLS of `line` over `pts` with Tukey's biweight at 4.685 robust scales
/// (1.4826 MAD, at least `min_scale` [normalised units]). Each iteration
/// measures the distances once, for the MAD and for the weights.
bool refineMotionLine(const std::vector<MotionPoint>& pts, double min_scale, MotionLine& line) {
  const std::size_t n = pts.size();
  std::vector<double> dist(n), den2(n), sorted(n);
  for (int it = 0; it < kIrlsIterations; ++it) {
    for (std::size_t k = 0; k < n; ++k) dist[k] = line.distance(pts[k], &den2[k]);
    sorted = dist;
    auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    const double cutoff = kTukey * std::max(kMadToSigma * *mid, min_scale);
    MotionLineSums sums;
    for (std::size_t k = 0; k < n; ++k) {
      double w = 0.0;
      if (tukeyPlaneWeight(dist[k], den2[k], cutoff, w)) sums.add(pts[k], line.c_c, w);
    }
    if (!sums.solve(line)) return false;
  }
  return true;
}

/// A robust line through `pts` (in time order), c_c the middle point's
/// centre: RANSAC over samples of 5 points (one per fifth of the time order;
/// 4 unknowns), each scored by its points within `inlier` [normalised
/// units], then refineMotionLine from the best. Deterministic for `seed`.
bool fitMotionLine(const std::vector<MotionPoint>& pts, double inlier, double min_scale, unsigned seed,
                   MotionLine& line) {
  const std::size_t n = pts.size();
  if (n < 2 * kSample) return false;
  line = MotionLine{};
  line.c_c = pts[n / 2].c;
  std::mt19937 rng(seed);
  std::vector<std::size_t> sample(kSample), scored;
  const std::size_t stride = std::max<std::size_t>(1, n / kScored);
  for (std::size_t k = 0; k < n; k += stride) scored.push_back(k);
  std::size_t best_count = 0;
  MotionLine best = line;
  for (int it = 0; it < kRansacIterations; ++it) {
    for (int q = 0; q < kSample; ++q) {
      std::uniform_int_distribution<std::size_t> pick(q * n / kSample, (q + 1) * n / kSample - 1);
      sample[q] = pick(rng);
    }
    MotionLine candidate = line;
    if (!solveMotionLine(pts, sample, false, 0.0, candidate)) continue;
    std::size_t count = 0;
    for (std::size_t k : scored) count += candidate.distance(pts[k]) <= inlier ? 1 : 0;
    if (count > best_count) best_count = count, best = candidate;
  }
  if (best_count < kSample) return false;
  line = best;
  return refineMotionLine(pts, min_scale, line);
}

/// Median of the points' distances to the line [normalised units].
double medianDistance(const std::vector<MotionPoint>& pts, const MotionLine& line) {
  if (pts.empty()) return std::numeric_limits<double>::infinity();
  std::vector<double> d;
  d.reserve(pts.size());
  for (const MotionPoint& p : pts) d.push_back(line.distance(p));
  auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

/// Sorts keys ascending, the order std::sort gives: LSD radix passes of 11
/// bits, each a stable counting sort, over the bits some key sets (a
/// window's cell-and-group marks use about 40 of 64, its cells about 27 of 32).
template <class Key>
void sortKeys(std::vector<Key>& keys) {
  if (keys.size() < 1024) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  constexpr int kBits = 8 * static_cast<int>(sizeof(Key));
  Key used = 0;
  for (Key k : keys) used |= k;
  std::vector<Key> moved(keys.size());
  std::vector<std::size_t> start(2049);
  for (int shift = 0; shift < kBits;) {
    if (((used >> shift) & 1u) == 0) {
      ++shift;
      continue;
    }
    std::fill(start.begin(), start.end(), 0);
    for (Key k : keys) ++start[((k >> shift) & 2047u) + 1];
    for (std::size_t d = 1; d < start.size(); ++d) start[d] += start[d - 1];
    for (Key k : keys) moved[start[(k >> shift) & 2047u]++] = k;
    keys.swap(moved);
    shift += 11;
  }
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(static_cast<std::size_t>(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

/// One cluster (or a group of joined clusters).
struct Group {
  std::vector<int> events;       ///< input indices
  std::vector<MotionPoint> fit;  ///< up to kFitEvents of them, evenly spread (kept only for motion_join_px)
  MotionLine line;
  bool fitted = false;
  bool explained = false;        ///< robust scale within the threshold
  double tolerance = 0.0;        ///< events within this of its line are its [normalised units]
  /// Polarities it takes: each that is at least kPolarityShare of its events
  /// (fragments of one edge joined before may hold both).
  bool on = false, off = false;
};

/// A window's clusters under one motion: the tabulated motion and each
/// cluster's line (step 1 of reassignToMotionLines).
struct WindowLines {
  std::optional<MotionTable> table;
  std::vector<Group> groups;
  int n_labels = 0;
  double t_lo = 0.0, t_hi = 0.0;
  double threshold = 0.0;  ///< [normalised units]
};

/// The event's point under the window's motion.
bool pointOf(const std::vector<Event>& events, const BearingFunction& bearing, const WindowLines& w, int i,
             MotionPoint& p) {
  const Event& e = events[static_cast<std::size_t>(i)];
  return w.table->point(e, bearing(Vec2(e.x, e.y)), p);
}

/// A cluster's line: from `start` (a joined group's tested line), else by
/// RANSAC; whether the motion explains it, its tolerance and polarities.
void fitGroup(const std::vector<Event>& events, const BearingFunction& bearing, double focal_px,
              const ClusterOptions& options, const WindowLines& w, Group& g, const MotionLine* start) {
  g.fit.clear();
  const std::size_t stride = std::max<std::size_t>(1, g.events.size() / kFitEvents);
  for (std::size_t k = 0; k < g.events.size(); k += stride) {
    MotionPoint p;
    if (pointOf(events, bearing, w, g.events[k], p)) g.fit.push_back(p);
  }
  if (start) g.line = *start;
  g.fitted = static_cast<int>(g.events.size()) >= options.min_cluster_size &&
             (start ? refineMotionLine(g.fit, kMinScalePx / focal_px, g.line)
                    : fitMotionLine(g.fit, w.threshold, kMinScalePx / focal_px, options.seed, g.line));
  const double scale = g.fitted ? kMadToSigma * medianDistance(g.fit, g.line) : 0.0;
  g.explained = g.fitted && scale <= w.threshold;
  g.tolerance = std::max(w.threshold, kToleranceScales * scale);
  std::size_t n_on = 0;
  for (int i : g.events) n_on += events[static_cast<std::size_t>(i)].on ? 1 : 0;
  const double share_on = static_cast<double>(n_on) / std::max<std::size_t>(g.events.size(), 1);
  g.on = share_on >= kPolarityShare;
  g.off = 1.0 - share_on >= kPolarityShare;
  // Only the fragment join reads the points again: without it they are freed
  // (72 B each, up to kFitEvents per cluster: about 35 MB for 1 M events).
  if (!(options.motion_join_px > 0.0)) std::vector<MotionPoint>().swap(g.fit);
}

/// Groups the clustered events and fits each cluster's line; false when
/// there is nothing to fit (no cluster, no finite time, no velocity).
bool fitWindowLines(const std::vector<Event>& events, const std::vector<int>& labels, const BearingFunction& bearing,
                    double focal_px, const MotionModel& motion, const Vec3& v, const ClusterOptions& options,
                    WindowLines& w) {
  if (!(options.motion_reassign_px > 0.0) || !bearing || !(focal_px > 0.0) || labels.size() != events.size() ||
      !v.allFinite() || !(v.norm() > 0.0))
    return false;
  w.threshold = options.motion_reassign_px / focal_px;
  w.t_lo = std::numeric_limits<double>::infinity(), w.t_hi = -w.t_lo;
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (!std::isfinite(events[i].t)) continue;
    w.t_lo = std::min(w.t_lo, events[i].t), w.t_hi = std::max(w.t_hi, events[i].t);
    w.n_labels = std::max(w.n_labels, labels[i] + 1);
  }
  if (w.n_labels == 0 || !(w.t_hi >= w.t_lo)) return false;
  w.groups.assign(static_cast<std::size_t>(w.n_labels), Group{});
  for (std::size_t i = 0; i < events.size(); ++i)
    if (labels[i] >= 0 && std::isfinite(events[i].t)) w.groups[labels[i]].events.push_back(static_cast<int>(i));
  w.table.emplace(motion, v.normalized(), w.t_lo, w.t_hi);
  // A cluster's line depends on its own events only: on options.threads
  // threads the same lines.
  parallelFor(w.groups.size(), options.threads,
              [&](std::size_t a) { fitGroup(events, bearing, focal_px, options, w, w.groups[a], nullptr); });
  return true;
}


}  // namespace

namespace {

/// One event's term of windowCost: min((d / T)^2, 1) to the line of its
/// cluster `l`; 1 in no fitted cluster or without a point (`p` null). Whether
/// the term needs the event's point: costNeedsPoint.
bool costNeedsPoint(const WindowLines& w, int l) { return l >= 0 && w.groups[l].fitted; }
double costTerm(const WindowLines& w, int l, const MotionPoint* p) {
  if (!p || !costNeedsPoint(w, l)) return 1.0;
  const double r = w.groups[l].line.distance(*p) / w.threshold;
  return std::min(r * r, 1.0);
}

/// The mean over the events with a finite time of costTerm, the clusters'
/// lines in `w`. On `threads` threads the terms are formed block by block
/// and added in event order: the one-thread sum, to the last bit.
double windowCost(const std::vector<Event>& events, const std::vector<int>& labels, const BearingFunction& bearing,
                  const WindowLines& w, int threads) {
  constexpr double kNoTerm = -1.0;  // an event without a finite time
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  const std::size_t parts = static_cast<std::size_t>(std::max(1, threads));
  std::vector<double> terms(std::min(events.size(), kBlock));
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t begin = 0; begin < events.size(); begin += kBlock) {
    const std::size_t count = std::min(kBlock, events.size() - begin);
    parallelFor(parts, threads, [&](std::size_t part) {
      for (std::size_t k = count * part / parts; k < count * (part + 1) / parts; ++k) {
        const std::size_t i = begin + k;
        if (!std::isfinite(events[i].t)) {
          terms[k] = kNoTerm;
          continue;
        }
        const int l = labels[i];
        MotionPoint p;
        const bool have = costNeedsPoint(w, l) && pointOf(events, bearing, w, static_cast<int>(i), p);
        terms[k] = costTerm(w, l, have ? &p : nullptr);
      }
    });
    for (std::size_t k = 0; k < count; ++k)
      if (terms[k] != kNoTerm) sum += terms[k], ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : NAN;
}

}  // namespace

/// The fitted lines a MotionLines holds.
struct MotionLinesFit {
  WindowLines w;
};

MotionLines::MotionLines() = default;
MotionLines::~MotionLines() = default;
MotionLines::MotionLines(MotionLines&&) noexcept = default;
MotionLines& MotionLines::operator=(MotionLines&&) noexcept = default;

bool MotionLines::fittedFor(const std::vector<int>& labels, const Vec3& v) const {
  return lines_ && v_ == v && labels_ == labels;
}

/// reassignToMotionLines' hold on a MotionLines' fitted lines.
struct MotionLinesAccess {
  static std::unique_ptr<MotionLinesFit> take(MotionLines& m) { return std::move(m.lines_); }
};

MotionLines fitMotionLines(const std::vector<Event>& events, const std::vector<int>& labels,
                           const BearingFunction& bearing, double focal_px, const MotionModel& motion, const Vec3& v,
                           const ClusterOptions& options) {
  MotionLines out;
  auto fit = std::make_unique<MotionLinesFit>();
  if (!fitWindowLines(events, labels, bearing, focal_px, motion, v, options, fit->w)) return out;
  out.cost_ = windowCost(events, labels, bearing, fit->w, options.threads);
  out.lines_ = std::move(fit);
  out.labels_ = labels;
  out.v_ = v;
  return out;
}

double motionCost(const std::vector<Event>& events, const std::vector<int>& labels, const BearingFunction& bearing,
                  double focal_px, const MotionModel& motion, const Vec3& v, const ClusterOptions& options) {
  return fitMotionLines(events, labels, bearing, focal_px, motion, v, options).cost();
}

MotionReassignReport reassignToMotionLines(const std::vector<Event>& events, std::vector<int>& labels,
                                           const BearingFunction& bearing, double focal_px,
                                           const MotionModel& motion, const Vec3& v, const ClusterOptions& options,
                                           MotionLines* prefit) {
  MotionReassignReport report;
  std::unique_ptr<MotionLinesFit> taken;
  // The cost of the clusters before (windowCost) is summed in event order:
  // on one thread and without joins the redraw's own pass over the events
  // adds it up, each event's point computed once for both.
  const std::size_t parts = static_cast<std::size_t>(std::max(1, options.threads));
  bool cost_in_pass = false;
  if (prefit && prefit->fittedFor(labels, v)) {
    report.cost = prefit->cost();
    taken = MotionLinesAccess::take(*prefit);
  } else {
    taken = std::make_unique<MotionLinesFit>();
    if (!fitWindowLines(events, labels, bearing, focal_px, motion, v, options, taken->w)) return report;
    cost_in_pass = parts == 1 && !(options.motion_join_px > 0.0);
    if (!cost_in_pass) report.cost = windowCost(events, labels, bearing, taken->w, options.threads);
  }
  WindowLines& w = taken->w;
  const double threshold = w.threshold;
  const int n_labels = w.n_labels;
  const double t_lo = w.t_lo, t_hi = w.t_hi;
  std::vector<Group>& groups = w.groups;
  for (const Group& g : groups) {
    report.n_lines += g.fitted ? 1 : 0;
    report.n_unexplained += g.fitted && !g.explained ? 1 : 0;
  }

  // 2. Fragments of one line join: both within motion_join_px of the joint line.
  UnionFind joined(n_labels);
  if (options.motion_join_px > 0.0) {
    const double join = options.motion_join_px / focal_px;
    // A few events of each: a pair is fitted jointly only when one's line
    // passes within kPrefilterPx of the other's events (median), from the
    // line that passes nearer.
    std::vector<std::vector<MotionPoint>> few(static_cast<std::size_t>(n_labels));
    for (int a = 0; a < n_labels; ++a) {
      const auto& fit = groups[a].fit;
      const std::size_t stride = std::max<std::size_t>(1, fit.size() / kPrefilterEvents);
      for (std::size_t k = 0; k < fit.size(); k += stride) few[a].push_back(fit[k]);
    }
    // Per group (a root of `joined`): the events its line explains, and its line.
    std::vector<std::vector<MotionPoint>> inliers(static_cast<std::size_t>(n_labels));
    std::vector<MotionLine> lines(static_cast<std::size_t>(n_labels));
    auto thin = [](std::vector<MotionPoint>& pts) {  // evenly, to kJoinEvents
      if (pts.size() <= kJoinEvents) return;
      std::vector<MotionPoint> kept;
      const double step = static_cast<double>(pts.size()) / kJoinEvents;
      for (std::size_t k = 0; k < kJoinEvents; ++k) kept.push_back(pts[static_cast<std::size_t>(k * step)]);
      pts.swap(kept);
    };
    for (int a = 0; a < n_labels; ++a) {
      lines[a] = groups[a].line;
      for (const MotionPoint& p : groups[a].fit)
        if (groups[a].line.distance(p) <= threshold) inliers[a].push_back(p);
      thin(inliers[a]);
    }
    for (int a0 = 0; a0 < n_labels; ++a0) {
      if (!groups[a0].explained) continue;
      for (int b0 = a0 + 1; b0 < n_labels; ++b0) {
        if (!groups[b0].explained) continue;
        const int a = joined.find(a0), b = joined.find(b0);
        if (a == b || (options.separate_polarity && !((groups[a].on && groups[b].on) || (groups[a].off && groups[b].off))))
          continue;
        const double ab = medianDistance(few[b0], lines[a]), ba = medianDistance(few[a0], lines[b]);
        if (std::min(ab, ba) > kPrefilterPx / focal_px) continue;
        // The two groups' explained events fitted together from least squares
        // (no other line's events among them); the whole groups are tested, so
        // a chain of joins cannot gather lines no one line explains.
        std::vector<MotionPoint> both = inliers[a];
        both.insert(both.end(), inliers[b].begin(), inliers[b].end());
        std::vector<std::size_t> all(both.size());
        std::iota(all.begin(), all.end(), std::size_t{0});
        MotionLine line;
        line.c_c = lines[a].c_c;
        if (!solveMotionLine(both, all, false, 0.0, line) || !refineMotionLine(both, kMinScalePx / focal_px, line))
          continue;
        if (!(medianDistance(inliers[a], line) <= join && medianDistance(inliers[b], line) <= join)) continue;
        joined.join(a, b);
        const int root = joined.find(a);
        lines[root] = line;
        thin(both);
        inliers[root] = std::move(both);
        inliers[root == a ? b : a].clear();
      }
    }
    std::vector<char> grew(static_cast<std::size_t>(n_labels), 0);
    for (int a = 0; a < n_labels; ++a) {
      const int root = joined.find(a);
      if (root == a) continue;
      Group& into = groups[root];
      grew[root] = 1;
      into.events.insert(into.events.end(), groups[a].events.begin(), groups[a].events.end());
      groups[a] = Group{};
      ++report.n_joined;
    }
    for (int a = 0; a < n_labels; ++a)
      if (grew[a]) {
        std::sort(groups[a].events.begin(), groups[a].events.end());
        fitGroup(events, bearing, focal_px, options, w, groups[a], &lines[a]);
      }
  }

  // 3. The neighbourhood of every explained group: the (cell, time bin) of its
  // events, +-1 in each; each event is then tested against the groups whose
  // neighbourhood holds it.
  const double bin_s = std::max(t_hi - t_lo, 1e-9) / kTimeBins;
  auto cellOf = [&](const Event& e) -> std::uint32_t {
    const auto cx = static_cast<std::uint32_t>(std::clamp(e.x / kCellPx, 0.0, 1023.0));
    const auto cy = static_cast<std::uint32_t>(std::clamp(e.y / kCellPx, 0.0, 1023.0));
    const auto tb = static_cast<std::uint32_t>(std::clamp((e.t - t_lo) / bin_s, 0.0, kTimeBins - 1.0));
    return (tb + 1) << 20 | (cy + 1) << 10 | (cx + 1);  // +1: room for the -1 neighbours
  };
  std::vector<std::uint64_t> marks;  // cell << 32 | group
  for (int a = 0; a < n_labels; ++a) {
    if (!groups[a].explained) continue;
    std::vector<std::uint32_t> cells;
    for (int i : groups[a].events) cells.push_back(cellOf(events[static_cast<std::size_t>(i)]));
    sortKeys(cells);
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    for (std::uint32_t c : cells)
      for (int dt = -1; dt <= 1; ++dt)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const std::int64_t cell = static_cast<std::int64_t>(c) + (static_cast<std::int64_t>(dt) << 20) +
                                      (static_cast<std::int64_t>(dy) << 10) + dx;
            marks.push_back(static_cast<std::uint64_t>(cell) << 32 | static_cast<std::uint32_t>(a));
          }
  }
  sortKeys(marks);
  marks.erase(std::unique(marks.begin(), marks.end()), marks.end());
  std::unordered_map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> range;  // cell -> [begin, end) of marks
  range.reserve(marks.size() / 2 + 1);
  for (std::size_t k = 0; k < marks.size();) {
    const auto cell = static_cast<std::uint32_t>(marks[k] >> 32);
    std::size_t e = k;
    while (e < marks.size() && static_cast<std::uint32_t>(marks[e] >> 32) == cell) ++e;
    range.emplace(cell, std::make_pair(static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(e)));
    k = e;
  }

  // 4. Every clustered event to the one line within the threshold.
  std::vector<int> label_of(static_cast<std::size_t>(n_labels));  // input label -> its group
  for (int a = 0; a < n_labels; ++a) label_of[a] = joined.find(a);
  std::vector<int> out(events.size(), -1);
  // Each event is judged alone: on options.threads threads, over contiguous
  // parts of the events, the same labels and counts.
  struct Counts {
    int moved = 0, ambiguous = 0, removed = 0;
  };
  std::vector<Counts> counts(parts);
  double cost_sum = 0.0;  // windowCost's sum and count, with cost_in_pass
  std::size_t cost_events = 0;
  parallelFor(parts, options.threads, [&](std::size_t part) {
    Counts& count = counts[part];
    const std::size_t i_end = events.size() * (part + 1) / parts;
    for (std::size_t i = events.size() * part / parts; i < i_end; ++i) {
      const Event& e = events[i];
      if (!std::isfinite(e.t)) continue;
      MotionPoint p;
      int have_point = -1;  // -1: not computed yet, else whether pointOf gave one
      auto point = [&] {
        if (have_point < 0) have_point = pointOf(events, bearing, w, static_cast<int>(i), p) ? 1 : 0;
        return have_point == 1;
      };
      if (cost_in_pass) {  // windowCost's term of this event (labels are the groups: no joins)
        ++cost_events;
        const int l = labels[i];
        cost_sum += costTerm(w, l, costNeedsPoint(w, l) && point() ? &p : nullptr);
      }
      const int current = labels[i] >= 0 ? label_of[labels[i]] : -1;
      if (current < 0) continue;           // unclustered events stay noise
      if (!groups[current].explained) {  // left as it was
        out[i] = current;
        continue;
      }
      const auto it = range.find(cellOf(e));
      int best = -1;
      double d1 = std::numeric_limits<double>::infinity(), d2 = d1, d_current = d1;
      if (it != range.end()) {
        if (point()) {
          for (std::uint32_t k = it->second.first; k < it->second.second; ++k) {
            const int a = static_cast<int>(marks[k] & 0xffffffffu);
            const Group& g = groups[a];
            if (options.separate_polarity && !(e.on ? g.on : g.off)) continue;
            const double d = g.line.distance(p) / g.tolerance;  // 1 at the group's tolerance
            if (a == current) d_current = d;
            if (d < d1) d2 = d1, d1 = d, best = a;
            else if (d < d2) d2 = d;
          }
        }
      }
      if (d1 <= 1.0 && d2 > 1.0) {
        out[i] = best;
        if (current != best) ++count.moved;
      } else if (d1 <= 1.0) {
        if (d_current <= 1.0) out[i] = current;  // its own line is one of those in reach
        ++count.ambiguous;
      } else if (current >= 0) {
        ++count.removed;
      }
    }
  });
  if (cost_in_pass) report.cost = cost_events > 0 ? cost_sum / static_cast<double>(cost_events) : NAN;
  for (const Counts& c : counts) {
    report.n_moved += c.moved;
    report.n_ambiguous += c.ambiguous;
    report.n_removed += c.removed;
  }

  // Groups left with too few events are noise; ids compact in order of first event.
  std::vector<int> size(static_cast<std::size_t>(n_labels), 0);
  for (int l : out)
    if (l >= 0) ++size[l];
  std::vector<int> id(static_cast<std::size_t>(n_labels), -1);
  int next = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const int l = out[i];
    if (l < 0) continue;
    if (size[l] < options.min_cluster_size) {
      out[i] = -1;
      continue;
    }
    if (id[l] < 0) id[l] = next++;
    out[i] = id[l];
  }
  labels.swap(out);
  return report;
}

}  // namespace celc
