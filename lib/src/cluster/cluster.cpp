#include "celc/cluster/cluster.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include "celc/core/parallel.hpp"

#include "cluster/internal.hpp"

namespace celc {

using detail::Group;
using detail::Regions;

ClusterMethod parseClusterMethod(const std::string& name) {
  if (name == "grid") return ClusterMethod::Grid;
  if (name == "pcl") return ClusterMethod::Pcl;
  throw std::invalid_argument("unknown cluster method '" + name + "' (expected grid or pcl)");
}

std::string toString(ClusterMethod method) {
  return method == ClusterMethod::Grid ? "grid" : "pcl";
}

std::string toString(ClusterStatus status) {
  switch (status) {
    case ClusterStatus::Ok: return "ok";
    case ClusterStatus::EmptyWindow: return "empty_window";
    case ClusterStatus::TooFewEvents: return "too_few_events";
    case ClusterStatus::NoClusters: return "no_clusters";
    case ClusterStatus::InvalidOptions: return "invalid_options";
  }
  return "unknown";
}

std::string clusterMethodProblem(ClusterMethod method) {
  return method == ClusterMethod::Pcl ? detail::pclGrowerError() : std::string();
}

std::string ClusterOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (!(c_max_px_per_s >= c_min_px_per_s)) e += "c_max_px_per_s: must be >= c_min_px_per_s; ";
  if (max_cluster_size < min_cluster_size) e += "max_cluster_size: must be >= min_cluster_size; ";
  if (recover_cell_px > 0.0 && recover_cell_px < 1.0)
    e += "recover_cell_px: 0 (off) or at least 1 px (a finer grid joins too few of a sparse edge's events); ";
  if (line_scale_ratio > 0.0 && line_scale_ratio < 1.0)
    e += "line_scale_ratio: 0 (off) or at least 1 (below 1 it drops most of a window's parts); ";
  return e;
}

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

bool validEvent(const Event& e) {
  return std::isfinite(e.t) && std::isfinite(e.x) && std::isfinite(e.y) && e.x >= 0.0f &&
         e.y >= 0.0f && e.x < 4096.0f && e.y < 4096.0f;
}

/// Valid events split into groups, t relative to t0.
std::vector<Group> makeGroups(const std::vector<Event>& events, double t0, bool separate) {
  std::vector<Group> groups(separate ? 2 : 1);
  if (separate) groups[1].on = false;
  size_t n_on = 0;
  for (const Event& e : events) n_on += e.on ? 1 : 0;
  for (Group& g : groups) {
    const size_t n = separate ? (g.on ? n_on : events.size() - n_on) : events.size();
    g.x.reserve(n), g.y.reserve(n), g.t.reserve(n), g.event_index.reserve(n);
  }
  for (size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    if (!validEvent(e)) continue;
    Group& g = groups[separate && !e.on ? 1 : 0];
    g.x.push_back(e.x);
    g.y.push_back(e.y);
    g.t.push_back(static_cast<float>(e.t - t0));
    g.event_index.push_back(static_cast<int>(i));
  }
  return groups;
}

struct PlaneFit {
  Vec3 centroid = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  double rms = 0.0;
  double area = 0.0;  ///< 12 sqrt(l1 l2) [px^2]: the area of a uniform rectangle with these variances
};

PlaneFit fitPlane(const Group& g, double c, const std::vector<int>& idx) {
  PlaneFit f;
  if (idx.empty()) return f;
  for (int i : idx) f.centroid += Vec3(g.x[i], g.y[i], c * g.t[i]);
  f.centroid /= static_cast<double>(idx.size());
  Mat3 cov = Mat3::Zero();
  for (int i : idx) {
    const Vec3 d = Vec3(g.x[i], g.y[i], c * g.t[i]) - f.centroid;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(idx.size());
  Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  f.normal = es.eigenvectors().col(0).normalized();
  f.rms = std::sqrt(std::max(0.0, es.eigenvalues()(0)));
  f.area = 12.0 * std::sqrt(std::max(0.0, es.eigenvalues()(1)) * std::max(0.0, es.eigenvalues()(2)));
  return f;
}

double spatialExtent(const Group& g, const std::vector<int>& idx) {
  if (idx.size() < 2) return 0.0;
  Vec2 m = Vec2::Zero();
  for (int i : idx) m += Vec2(g.x[i], g.y[i]);
  m /= static_cast<double>(idx.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (int i : idx) {
    const Vec2 d = Vec2(g.x[i], g.y[i]) - m;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  const Vec2 axis = es.eigenvectors().col(1);
  double lo = 1e300, hi = -1e300;
  for (int i : idx) {
    const double s = axis.dot(Vec2(g.x[i], g.y[i]) - m);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  return hi - lo;
}

/// Sequential RANSAC: extracts up to opt.max_split planes from a non-planar region.
std::vector<std::vector<int>> splitPlanes(const Group& g, double c, std::vector<int> idx,
                                          const ClusterOptions& opt, std::mt19937& rng) {
  std::vector<std::vector<int>> parts;
  const double thr = opt.ransac_threshold_px;
  auto pt = [&](int i) { return Vec3(g.x[i], g.y[i], c * g.t[i]); };
  for (int part = 0; part < opt.max_split; ++part) {
    if (static_cast<int>(idx.size()) < opt.min_cluster_size) break;
    const size_t n = idx.size();
    const size_t stride = std::max<size_t>(1, n / 1000);  // inliers counted on <= ~1000 points
    std::uniform_int_distribution<size_t> pick(0, n - 1);
    Vec3 best_n = Vec3::Zero(), best_p = Vec3::Zero();
    size_t best_count = 0;
    for (int it = 0; it < 150; ++it) {
      const Vec3 a = pt(idx[pick(rng)]), b = pt(idx[pick(rng)]), c = pt(idx[pick(rng)]);
      Vec3 nrm = (b - a).cross(c - a);
      if (nrm.norm() < 1e-6) continue;
      nrm.normalize();
      size_t count = 0;
      for (size_t k = 0; k < n; k += stride)
        if (std::fabs(nrm.dot(pt(idx[k]) - a)) < thr) ++count;
      if (count > best_count) best_count = count, best_n = nrm, best_p = a;
    }
    if (best_count == 0) break;
    // Refine: PCA on the close inliers (half the threshold, so that a nearby
    // second plane pulls little), then inliers again at the threshold.
    std::vector<int> in;
    for (int i : idx)
      if (std::fabs(best_n.dot(pt(i) - best_p)) < 0.5 * thr) in.push_back(i);
    if (static_cast<int>(in.size()) < opt.min_cluster_size) break;
    const PlaneFit f = fitPlane(g, c, in);
    in.clear();
    std::vector<int> rest;
    for (int i : idx) (std::fabs(f.normal.dot(pt(i) - f.centroid)) < thr ? in : rest).push_back(i);
    if (static_cast<int>(in.size()) < opt.min_cluster_size) break;
    parts.push_back(std::move(in));
    idx.swap(rest);
  }
  return parts;
}

struct GroupOutput {
  std::vector<std::vector<int>> clusters;  // event indices
  std::vector<LossReason> loss;            // per group point: where it went when in no cluster
  std::vector<ClusterStats> stats;
  int n_regions = 0, n_split = 0, n_rejected_planar = 0, n_rejected_small = 0;
  ClusterLosses left_out;  // invalid stays 0: a group holds valid events only
  double ms_normals = 0.0, ms_grow = 0.0, ms_post = 0.0;
  double smoothness_deg = 0.0;  // the growing's angle (0: the group did not grow)
};

GroupOutput processGroup(const std::vector<Event>& events, const Group& g,
                         const detail::GridIndex* index, double c,
                         const ClusterOptions& opt, int threads,
                         detail::GridNormals* normals = nullptr) {
  GroupOutput out;
  out.loss.assign(g.size(), LossReason::NoRegion);
  if (static_cast<int>(g.size()) < opt.min_cluster_size) {  // not grown
    out.left_out.no_region = static_cast<int>(g.size());
    return out;
  }
  auto t_start = Clock::now();
  const Regions regions = opt.method == ClusterMethod::Pcl || index == nullptr
                              ? detail::growPcl(g, c, opt, threads)
                              : detail::growGrid(*index, c, opt, threads, normals);
  out.ms_normals = regions.ms_normals;
  out.smoothness_deg = opt.method == ClusterMethod::Pcl || index == nullptr ? opt.smoothness_deg : regions.smoothness_deg;
  out.ms_grow = msSince(t_start) - regions.ms_normals;
  t_start = Clock::now();
  // Index lists of the regions large enough to matter.
  std::vector<int> sizes(regions.count, 0);
  for (int l : regions.label)
    if (l >= 0) ++sizes[l];
  std::vector<int> slot(regions.count, -1);
  std::vector<std::vector<int>> lists;
  for (int r = 0; r < regions.count; ++r) {
    if (sizes[r] >= opt.min_cluster_size && sizes[r] <= opt.max_cluster_size) {
      slot[r] = static_cast<int>(lists.size());
      lists.emplace_back();
      lists.back().reserve(sizes[r]);
    } else if (sizes[r] > 0) {
      ++out.n_rejected_small;
      out.left_out.small_region += sizes[r];
    }
  }
  int in_lists = 0;  // events of the regions checked below
  for (int l : regions.label) {
    if (l < 0) ++out.left_out.no_region;
    else if (slot[l] >= 0) ++in_lists;
  }
  for (size_t i = 0; i < regions.label.size(); ++i) {
    const int l = regions.label[i];
    if (l >= 0 && slot[l] >= 0) lists[slot[l]].push_back(static_cast<int>(i));
    if (l >= 0) out.loss[i] = slot[l] >= 0 ? LossReason::OffPlanes : LossReason::SmallRegion;
  }
  out.n_regions = static_cast<int>(lists.size());
  std::mt19937 rng(opt.seed);
  auto failChecks = [&](const std::vector<int>& idx) {
    ++out.n_rejected_small;
    out.left_out.failed_checks += static_cast<int>(idx.size());
    for (int i : idx) out.loss[static_cast<std::size_t>(i)] = LossReason::FailedChecks;
  };
  auto accept = [&](std::vector<int>&& idx, const PlaneFit& f) {
    if (static_cast<int>(idx.size()) < opt.min_cluster_size) {
      failChecks(idx);
      return;
    }
    double t_lo = 1e300, t_hi = -1e300;
    for (int i : idx) {
      t_lo = std::min(t_lo, events[g.event_index[i]].t);
      t_hi = std::max(t_hi, events[g.event_index[i]].t);
    }
    const double extent = spatialExtent(g, idx);
    const double density = static_cast<double>(idx.size()) / std::max(f.area, 1.0);
    if (t_hi - t_lo < opt.min_time_span_s || extent < opt.min_extent_px ||
        density < opt.min_density_per_px2) {
      failChecks(idx);
      return;
    }
    ClusterStats s;
    s.size = static_cast<int>(idx.size());
    s.on = g.on;
    s.t_begin = t_lo;
    s.t_end = t_hi;
    s.plane_normal = f.normal;
    s.centroid = f.centroid;
    s.plane_rms_px = f.rms;
    s.density_per_px2 = density;
    s.extent_px = extent;
    const double nxy = f.normal.head<2>().norm();
    s.speed_px_per_s = nxy > 1e-9 ? c * std::fabs(f.normal.z()) / nxy : 0.0;
    std::vector<int> ev(idx.size());
    for (size_t k = 0; k < idx.size(); ++k) {
      ev[k] = g.event_index[idx[k]];
      out.loss[static_cast<std::size_t>(idx[k])] = LossReason::None;
    }
    size_t n_on = 0;
    for (int e : ev) n_on += events[e].on ? 1 : 0;
    s.on = 2 * n_on >= ev.size();  // the group's polarity, or the majority when merged
    out.stats.push_back(s);
    out.clusters.push_back(std::move(ev));
  };
  for (auto& idx : lists) {
    const PlaneFit f = fitPlane(g, c, idx);
    if (f.rms <= opt.max_plane_rms_px) {
      accept(std::move(idx), f);
      continue;
    }
    auto parts = splitPlanes(g, c, std::move(idx), opt, rng);
    if (parts.size() > 1) ++out.n_split;
    bool any = false;
    for (auto& p : parts) {
      const PlaneFit pf = fitPlane(g, c, p);
      if (pf.rms <= opt.max_plane_rms_px) {
        accept(std::move(p), pf);
        any = true;
      }
    }
    if (!any) ++out.n_rejected_planar;
  }
  int accepted = 0;
  for (const auto& c : out.clusters) accepted += static_cast<int>(c.size());
  out.left_out.off_planes = in_lists - accepted - out.left_out.failed_checks;
  out.ms_post = msSince(t_start);
  return out;
}

double initialTimeScale(const std::vector<Event>& events, const ClusterOptions& opt) {
  double tmin = 1e300, tmax = -1e300, xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (const Event& e : events) {
    if (!validEvent(e)) continue;
    tmin = std::min(tmin, e.t), tmax = std::max(tmax, e.t);
    xmin = std::min<double>(xmin, e.x), xmax = std::max<double>(xmax, e.x);
    ymin = std::min<double>(ymin, e.y), ymax = std::max<double>(ymax, e.y);
  }
  if (!(tmax > tmin)) return opt.c_max_px_per_s;
  const double diag = std::hypot(xmax - xmin + 1.0, ymax - ymin + 1.0);
  return std::clamp(0.1 * diag / (tmax - tmin), opt.c_min_px_per_s, opt.c_max_px_per_s);
}

}  // namespace

double estimateTimeScale(const std::vector<Event>& events, const ClusterOptions& opt) {
  double t0 = 1e300;
  size_t n_valid = 0;
  for (const Event& e : events)
    if (validEvent(e)) t0 = std::min(t0, e.t), ++n_valid;
  if (n_valid < 50) return 0.0;
  const std::vector<Group> groups = makeGroups(events, t0, opt.separate_polarity);
  std::vector<detail::GridIndex> indexes;
  std::vector<const detail::GridIndex*> ptrs;
  indexes.reserve(groups.size());
  for (const Group& g : groups) indexes.emplace_back(g);
  for (const auto& ix : indexes) ptrs.push_back(&ix);
  return detail::estimateTimeScaleOnIndex(ptrs, initialTimeScale(events, opt), opt);
}

ClusterResult clusterEvents(const std::vector<Event>& events, const ClusterOptions& opt) {
  const auto t_start = Clock::now();
  ClusterResult res;
  res.n_events = static_cast<int>(events.size());
  res.labels.assign(events.size(), -1);
  const std::string err = opt.validate();
  if (!err.empty()) {
    res.status = ClusterStatus::InvalidOptions;
    res.message = err;
    return res;
  }
  if (std::string why = clusterMethodProblem(opt.method); !why.empty()) {
    res.status = ClusterStatus::InvalidOptions;
    res.message = std::move(why);
    return res;
  }
  if (events.empty()) {
    res.status = ClusterStatus::EmptyWindow;
    res.message = "no events";
    return res;
  }
  double t0 = 1e300;
  int n_valid = 0;
  for (const Event& e : events)
    if (validEvent(e)) t0 = std::min(t0, e.t), ++n_valid;
  res.left_out.invalid = res.n_events - n_valid;
  res.loss.assign(events.size(), LossReason::Invalid);
  if (n_valid < opt.min_cluster_size) {
    res.left_out.no_region = n_valid;  // not grown
    for (std::size_t i = 0; i < events.size(); ++i)
      if (validEvent(events[i])) res.loss[i] = LossReason::NoRegion;
    res.status = n_valid == 0 ? ClusterStatus::EmptyWindow : ClusterStatus::TooFewEvents;
    res.message = std::to_string(n_valid) + " valid events, fewer than min_cluster_size";
    return res;
  }
  res.t0 = t0;
  const std::vector<Group> groups = makeGroups(events, t0, opt.separate_polarity);
  auto t_c = Clock::now();
  // Grid indexes: used by the grid grower and by the automatic time scale.
  std::vector<detail::GridIndex> indexes;
  std::vector<const detail::GridIndex*> ptrs;
  const bool need_index = opt.method == ClusterMethod::Grid || opt.c_px_per_s <= 0.0;
  if (need_index) {
    indexes.reserve(groups.size());
    if (groups.size() == 2 && opt.threads >= 2) {  // the two polarities' indexes side by side
      indexes.emplace_back(Group{});
      indexes.emplace_back(Group{});
      parallelFor(2, 2, [&](std::size_t k) { indexes[k] = detail::GridIndex(groups[k]); });
    } else {
      for (const Group& g : groups) indexes.emplace_back(g);
    }
    for (const auto& ix : indexes) ptrs.push_back(&ix);
  }
  double c = opt.c_px_per_s;
  if (c <= 0.0) {
    const double c0 = initialTimeScale(events, opt);
    const double speed = detail::estimateTimeScaleOnIndex(ptrs, c0, opt);  // median normal speed
    c = speed > 0.0 ? std::clamp(opt.c_speed_factor * speed, opt.c_min_px_per_s, opt.c_max_px_per_s) : c0;
  }
  res.c_px_per_s = c;
  res.ms_time_scale = msSince(t_c);

  std::vector<GroupOutput> outs(groups.size());
  auto indexOf = [&](size_t k) {
    return opt.method == ClusterMethod::Grid ? &indexes[k] : nullptr;
  };
  if (groups.size() == 2 && opt.threads >= 2) {
    const int per = std::max(1, opt.threads / 2);
    // Grid: normals (the largest part) group after group with all threads, split
    // by event count; then growing and checks of the two groups in parallel.
    std::vector<detail::GridNormals> normals(2);
    double ms_normals = 0.0;
    if (opt.method == ClusterMethod::Grid) {
      for (size_t k = 0; k < 2; ++k) {
        if (static_cast<int>(groups[k].size()) < opt.min_cluster_size) continue;
        normals[k] = detail::computeGridNormals(indexes[k], c, opt, opt.threads);
        ms_normals += normals[k].ms;
      }
    }
    parallelFor(2, 2, [&](std::size_t k) {
      outs[k] = processGroup(events, groups[k], indexOf(k), c, opt, per, &normals[k]);
    });
    outs[0].ms_normals += ms_normals;
  } else {
    for (size_t k = 0; k < groups.size(); ++k)
      outs[k] = processGroup(events, groups[k], indexOf(k), c, opt, opt.threads);
  }
  // Clusters ordered by start time, labelled 0..K-1.
  struct Item {
    ClusterStats* s;
    std::vector<int>* ev;
  };
  std::vector<Item> items;
  for (std::size_t k = 0; k < groups.size(); ++k)
    for (std::size_t i = 0; i < groups[k].size(); ++i)
      res.loss[static_cast<std::size_t>(groups[k].event_index[i])] = outs[k].loss[i];
  for (auto& o : outs) {
    if (o.smoothness_deg > 0.0) res.smoothness_deg = std::max(res.smoothness_deg, o.smoothness_deg);
    res.n_regions += o.n_regions;
    res.n_split += o.n_split;
    res.n_rejected_planar += o.n_rejected_planar;
    res.n_rejected_small += o.n_rejected_small;
    res.left_out.no_region += o.left_out.no_region;
    res.left_out.small_region += o.left_out.small_region;
    res.left_out.failed_checks += o.left_out.failed_checks;
    res.left_out.off_planes += o.left_out.off_planes;
    res.ms_normals += o.ms_normals;
    res.ms_grow += o.ms_grow;
    res.ms_post += o.ms_post;
    for (size_t k = 0; k < o.stats.size(); ++k) items.push_back({&o.stats[k], &o.clusters[k]});
  }
  std::stable_sort(items.begin(), items.end(),
                   [](const Item& a, const Item& b) { return a.s->t_begin < b.s->t_begin; });
  for (const Item& it : items) {
    ClusterStats s = *it.s;
    s.id = static_cast<int>(res.clusters.size());
    for (int e : *it.ev) res.labels[e] = s.id;
    res.n_clustered += s.size;
    res.clusters.push_back(s);
  }
  res.status = res.clusters.empty() ? ClusterStatus::NoClusters : ClusterStatus::Ok;
  if (res.clusters.empty()) res.message = "no region passed the checks";
  res.ms_total = msSince(t_start);
  return res;
}

}  // namespace celc
