// Fast region grower: events bucketed per pixel and sorted by c*t inside each
// bucket, so the neighbours of an event are the events of the (2r+1)^2 pixels
// around it whose c*t lies within +-time_radius_px (a binary search per pixel).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "celc/core/parallel.hpp"

#include "cluster/internal.hpp"

namespace celc::detail {

namespace {

/// std::lround(v) without a call: for v >= 0, v + 0.5 in double is exact
/// (or, below 2^-30, still under 1) and truncation gives the nearest whole
/// number, halves away from zero. A group's coordinates lie in [0, 4096).
int nearestPixel(float v) {
  return v >= 0.0f ? static_cast<int>(static_cast<double>(v) + 0.5) : static_cast<int>(std::lround(v));
}

}  // namespace

GridIndex::GridIndex(const Group& g) {
  const size_t n = g.size();
  if (n == 0) return;
  int xmin = 1 << 30, ymin = 1 << 30, xmax = -(1 << 30), ymax = -(1 << 30);
  std::vector<int> pix(n);
  for (size_t i = 0; i < n; ++i) {
    const int xi = nearestPixel(g.x[i]), yi = nearestPixel(g.y[i]);
    xmin = std::min(xmin, xi), xmax = std::max(xmax, xi);
    ymin = std::min(ymin, yi), ymax = std::max(ymax, yi);
  }
  w_ = xmax - xmin + 1;
  h_ = ymax - ymin + 1;
  for (size_t i = 0; i < n; ++i)
    pix[i] = (nearestPixel(g.y[i]) - ymin) * w_ + nearestPixel(g.x[i]) - xmin;
  // Points in order of increasing time (usually already so).
  std::vector<int> by_time(n);
  std::iota(by_time.begin(), by_time.end(), 0);
  if (!std::is_sorted(g.t.begin(), g.t.end()))
    std::stable_sort(by_time.begin(), by_time.end(), [&](int a, int b) { return g.t[a] < g.t[b]; });
  // Counting sort by pixel, stable: time ascending inside each bucket.
  start_.assign(static_cast<size_t>(w_) * h_ + 1, 0);
  for (size_t i = 0; i < n; ++i) ++start_[pix[i] + 1];
  for (size_t p = 1; p < start_.size(); ++p) start_[p] += start_[p - 1];
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  point_.resize(n);
  cells_.resize(n);
  by_time_.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const int i = by_time[j];
    const int k = fill[pix[i]]++;
    point_[k] = i;
    cells_[k] = {g.t[i], static_cast<int16_t>(pix[i] % w_), static_cast<int16_t>(pix[i] / w_)};
    by_time_[j] = k;
  }
}

namespace {

/// Normal (eigenvector of the smallest eigenvalue) and curvature from the
/// central moments of a neighbourhood; false when degenerate. The eigenvalues
/// of the symmetric A are q + 2 p cos(phi + 2 pi k / 3), with q = tr(A) / 3,
/// p^2 = |A - q I|_F^2 / 6 and cos(3 phi) = det((A - q I) / p) / 2; the
/// smallest one's eigenvector is orthogonal to every row of A - lambda_0 I,
/// the largest cross product of two of them (Eigen's computeDirect also
/// finds the other two eigenvectors, which the grower does not use).
bool normalFromCovariance(const Eigen::Matrix3d& cov, float* out_n, float* out_curv) {
  const double a = cov(0, 0), b = cov(1, 1), c = cov(2, 2), d = cov(0, 1), e = cov(1, 2), f = cov(0, 2);
  const double sum = a + b + c, q = sum / 3.0;
  const double off = d * d + e * e + f * f;
  const double p = std::sqrt(((a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2.0 * off) / 6.0);
  // Degenerate: all points on one spot or one line (e.g. a single hot pixel).
  if (!(sum > 1e-9) || !(p > 0.0)) return false;
  const double ba = (a - q) / p, bb = (b - q) / p, bc = (c - q) / p, bd = d / p, be = e / p, bf = f / p;
  const double det = ba * (bb * bc - be * be) - bd * (bd * bc - be * bf) + bf * (bd * be - bb * bf);
  const double phi = std::acos(std::clamp(0.5 * det, -1.0, 1.0)) / 3.0;
  const double l2 = q + 2.0 * p * std::cos(phi);                     // largest
  const double l0 = q + 2.0 * p * std::cos(phi + 2.0 * M_PI / 3.0);  // smallest
  const double l1 = sum - l0 - l2;
  if (l1 < 1e-3 * sum || l1 < 1e-4) return false;
  const Eigen::Vector3d r0(a - l0, d, f), r1(d, b - l0, e), r2(f, e, c - l0);
  const Eigen::Vector3d c01 = r0.cross(r1), c02 = r0.cross(r2), c12 = r1.cross(r2);
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  const Eigen::Vector3d& best = n01 >= n02 && n01 >= n12 ? c01 : (n02 >= n12 ? c02 : c12);
  const double norm2 = std::max({n01, n02, n12});
  if (!(norm2 > 0.0)) return false;
  const Eigen::Vector3d nrm = best / std::sqrt(norm2);
  out_n[0] = static_cast<float>(nrm(0));
  out_n[1] = static_cast<float>(nrm(1));
  out_n[2] = static_cast<float>(nrm(2));
  *out_curv = static_cast<float>(std::max(0.0, l0) / sum);
  return true;
}

}  // namespace

bool normalFromSums(const double s[10], double c, int min_neighbours, float* out_n, float* out_curv) {
  *out_curv = 2.0f;
  const double s0 = s[0];
  if (s0 < min_neighbours) return false;
  // Central moments of (dx, dy, c t).
  const double mx = s[1] / s0, my = s[2] / s0, mt = s[6] / s0;
  Eigen::Matrix3d cov;
  cov(0, 0) = s[3] / s0 - mx * mx;
  cov(0, 1) = cov(1, 0) = s[4] / s0 - mx * my;
  cov(1, 1) = s[5] / s0 - my * my;
  cov(0, 2) = cov(2, 0) = c * (s[8] / s0 - mx * mt);
  cov(1, 2) = cov(2, 1) = c * (s[9] / s0 - my * mt);
  cov(2, 2) = c * c * std::max(0.0, s[7] / s0 - mt * mt);
  if (normalFromCovariance(cov, out_n, out_curv)) return true;
  *out_curv = 2.0f;
  return false;
}

bool GridIndex::normal(int k, double c, const ClusterOptions& opt, float* out_n,
                       float* out_curv) const {
  float s[3] = {0, 0, 0}, ss[6] = {0, 0, 0, 0, 0, 0};
  int cnt = 0;
  const Cell& c0 = cells_[k];
  const float cf = static_cast<float>(c);
  forNeighbours(k, opt.grid_radius_px, static_cast<float>(opt.time_radius_px / c), [&](int j) {
    const Cell& q = cells_[j];
    const float dx = static_cast<float>(q.x - c0.x), dy = static_cast<float>(q.y - c0.y);
    const float dz = cf * (q.t - c0.t);
    s[0] += dx, s[1] += dy, s[2] += dz;
    ss[0] += dx * dx, ss[1] += dx * dy, ss[2] += dx * dz;
    ss[3] += dy * dy, ss[4] += dy * dz, ss[5] += dz * dz;
    ++cnt;
  });
  if (cnt < opt.min_neighbours) return false;
  const double inv = 1.0 / cnt;
  const double m0 = s[0] * inv, m1 = s[1] * inv, m2 = s[2] * inv;
  Eigen::Matrix3d cov;
  cov(0, 0) = ss[0] * inv - m0 * m0;
  cov(0, 1) = cov(1, 0) = ss[1] * inv - m0 * m1;
  cov(0, 2) = cov(2, 0) = ss[2] * inv - m0 * m2;
  cov(1, 1) = ss[3] * inv - m1 * m1;
  cov(1, 2) = cov(2, 1) = ss[4] * inv - m1 * m2;
  cov(2, 2) = ss[5] * inv - m2 * m2;
  return normalFromCovariance(cov, out_n, out_curv);
}

void GridIndex::allNormals(double c, const ClusterOptions& opt, int threads, float* nrm,
                           float* curv) const {
  const int r = opt.grid_radius_px;
  const double tau = opt.time_radius_px / c;
  const float reuse_dt = static_cast<float>(opt.normal_reuse_px / c);
  const int n_pix = w_ * h_;
  // Prefix sums of t and t^2 (t relative to the window start) over the cells, so
  // that the moments of any run of a bucket are two differences.
  const size_t n = size();
  struct Prefix {
    double t, tt;
  };
  std::vector<Prefix> pre(n + 1, Prefix{0.0, 0.0});
  for (size_t k = 0; k < n; ++k) {
    const double t = cells_[k].t;
    pre[k + 1] = {pre[k].t + t, pre[k].tt + t * t};
  }
  // The normals of the events of pixels p_begin .. p_end - 1.
  auto work = [&](int p_begin, int p_end) {
    // Per pixel, its run within the current event's time window: bucket
    // positions [lo, hi), the events with t_lo <= t <= t_hi. Both only grow,
    // as the sweep's time does. `last`: the pixel's last event whose normal
    // was computed.
    std::vector<int> lo(start_.begin(), start_.end() - 1), hi(lo), last(static_cast<size_t>(n_pix), -1);
    size_t entered = 0, left = 0;  // sweep positions in by_time_
    for (size_t j = 0; j < n; ++j) {
      const int k = by_time_[j];
      const Cell& ck = cells_[k];
      const int p = ck.y * w_ + ck.x;
      if (p < p_begin || p >= p_end) continue;
      const float tk = ck.t;
      // An event right after one of the same pixel shares its neighbourhood
      // (within reuse_dt): take its normal instead of recomputing it.
      const int prev = last[static_cast<size_t>(p)];
      if (prev >= 0 && tk - cells_[prev].t <= reuse_dt) {
        std::copy_n(&nrm[3 * static_cast<size_t>(prev)], 3, &nrm[3 * static_cast<size_t>(k)]);
        curv[k] = curv[prev];
        continue;
      }
      last[static_cast<size_t>(p)] = k;
      const float t_hi = static_cast<float>(tk + tau), t_lo = static_cast<float>(tk - tau);
      for (; entered < n && cells_[by_time_[entered]].t <= t_hi; ++entered) {
        const Cell& q = cells_[by_time_[entered]];
        ++hi[static_cast<size_t>(q.y * w_ + q.x)];
      }
      for (; left < n && cells_[by_time_[left]].t < t_lo; ++left) {
        const Cell& q = cells_[by_time_[left]];
        ++lo[static_cast<size_t>(q.y * w_ + q.x)];
      }
      // Sums over the neighbourhood (normalFromSums' order); a pixel without
      // events in the window adds exact zeros.
      double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0, s8 = 0, s9 = 0;
      for (int y = std::max(0, ck.y - r); y <= std::min(h_ - 1, ck.y + r); ++y) {
        const double dy = y - ck.y;
        for (int x = std::max(0, ck.x - r); x <= std::min(w_ - 1, ck.x + r); ++x) {
          const size_t q = static_cast<size_t>(y) * w_ + x;
          const int l = lo[q], h = hi[q];
          const double dx = x - ck.x;
          const double M = h - l, T = pre[h].t - pre[l].t, TT = pre[h].tt - pre[l].tt;
          s0 += M, s1 += dx * M, s2 += dy * M, s3 += dx * dx * M;
          s4 += dx * dy * M, s5 += dy * dy * M, s6 += T, s7 += TT;
          s8 += dx * T, s9 += dy * T;
        }
      }
      const double sums[10] = {s0, s1, s2, s3, s4, s5, s6, s7, s8, s9};
      normalFromSums(sums, c, opt.min_neighbours, &nrm[3 * static_cast<size_t>(k)], &curv[k]);
    }
  };
  threads = std::max(1, std::min(threads, static_cast<int>(size() / 4096) + 1));
  if (threads == 1) {
    work(0, n_pix);
    return;
  }
  // Split the pixels so that each worker gets about the same number of events;
  // part t covers pixels [bounds[t], bounds[t + 1]).
  std::vector<int> bounds{0};
  for (int t = 0; t < threads; ++t) {
    const size_t target = size() * static_cast<size_t>(t + 1) / static_cast<size_t>(threads);
    int p1 = t + 1 == threads
                 ? n_pix
                 : static_cast<int>(std::upper_bound(start_.begin(), start_.end(), static_cast<int>(target)) -
                                    start_.begin()) - 1;
    bounds.push_back(std::clamp(p1, bounds.back(), n_pix));
  }
  parallelFor(static_cast<std::size_t>(threads), threads,
              [&](std::size_t t) { work(bounds[t], bounds[t + 1]); });
}

GridNormals computeGridNormals(const GridIndex& index, double c, const ClusterOptions& opt,
                               int threads) {
  GridNormals g;
  const size_t n = index.size();
  g.nrm.assign(3 * n, 0.0f);
  g.curv.assign(n, 2.0f);
  const auto t0 = std::chrono::steady_clock::now();
  if (n > 0) index.allNormals(c, opt, threads, g.nrm.data(), g.curv.data());
  g.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

Regions growGrid(const GridIndex& index, double c, const ClusterOptions& opt, int threads,
                 GridNormals* normals) {
  Regions out;
  const int n = static_cast<int>(index.size());
  out.label.assign(n, -1);
  if (n == 0) return out;
  // Normals and curvature in bucket order; curvature 2 marks "no normal".
  GridNormals own;
  if (normals == nullptr || normals->curv.size() != static_cast<size_t>(n)) {
    own = computeGridNormals(index, c, opt, threads);
    normals = &own;
    out.ms_normals = own.ms;
  }
  const std::vector<float>& nrm = normals->nrm;
  const std::vector<float>& curv = normals->curv;
  // Region growing with pcl::RegionGrowing's criteria (smooth mode): a region
  // spreads from point i to a neighbour j when |n_i . n_j| >= cos(smoothness)
  // and continues from j only when j's curvature is below the threshold. The
  // low-curvature points a region reaches are therefore exactly a connected
  // component of the graph "low-curvature neighbours with similar normals",
  // found here with union-find in one sweep; each high-curvature point then
  // joins the region of its first low-curvature neighbour with a similar
  // normal (PCL gives it to the region that reaches it first).
  out.smoothness_deg = growingAngleDeg(index, c, opt, *normals);
  const float cos_thr = static_cast<float>(std::cos(out.smoothness_deg * M_PI / 180.0));
  const float curv_thr = static_cast<float>(opt.curvature_threshold);
  std::vector<int> parent(n), attach(n, -1);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  auto similar = [&](int a, int b) {
    const float* na = &nrm[3 * static_cast<size_t>(a)];
    const float* nb = &nrm[3 * static_cast<size_t>(b)];
    return std::fabs(na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) >= cos_thr;
  };
  auto valid = [&](int k) { return curv[k] <= 1.0f; };  // pairs with an invalid k change nothing
  // A root is its component's smallest index (the larger root is linked under
  // the smaller), so the regions do not depend on the order of the unions.
  // sweepPairs gives k's pairs one after another: k's root is found once per
  // k and follows k's own unions.
  int root_of = -1, root = -1;  // the event whose root is held, and that root
  index.sweepPairs(opt.grow_radius_px, opt.grow_time_radius_px / c, valid, [&](int k, int j) {
    const bool lk = curv[k] < curv_thr, lj = curv[j] < curv_thr;
    if (lk && lj) {
      if (k != root_of) root_of = k, root = find(k);
      // Already in one region (the common case): nothing to test.
      const int rj = find(j);
      if (root != rj && similar(k, j)) {
        parent[std::max(root, rj)] = std::min(root, rj);
        root = std::min(root, rj);
      }
    } else if (lk != lj) {
      const int hi = lk ? j : k, lo = lk ? k : j;  // high- and low-curvature point
      if (curv[hi] <= 1.0f && attach[hi] < 0 && similar(hi, lo)) attach[hi] = lo;
    }
  });
  std::vector<int> region_of(n, -1);
  int region = 0;
  for (int k = 0; k < n; ++k) {
    int root = -1;
    if (curv[k] < curv_thr) root = find(k);
    else if (attach[k] >= 0) root = find(attach[k]);
    if (root < 0) continue;
    if (region_of[root] < 0) region_of[root] = region++;
    out.label[index.point(k)] = region_of[root];
  }
  out.count = region;
  return out;
}

double medianNeighbourAngleDeg(const GridIndex& index, double c, const ClusterOptions& opt,
                               const GridNormals& normals) {
  const size_t n = index.size();
  const size_t stride = std::max<size_t>(1, n / 4000);
  const float curv_thr = static_cast<float>(opt.curvature_threshold);
  const float dt = static_cast<float>(opt.grow_time_radius_px / c);
  std::vector<float> cosines;
  for (size_t k = stride / 2; k < n; k += stride) {
    if (!(normals.curv[k] < curv_thr)) continue;
    const float* a = &normals.nrm[3 * k];
    index.forNeighbours(static_cast<int>(k), opt.grow_radius_px, dt, [&](int j) {
      if (j == static_cast<int>(k) || !(normals.curv[j] < curv_thr)) return;
      const float* b = &normals.nrm[3 * static_cast<size_t>(j)];
      cosines.push_back(std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]));
    });
  }
  if (cosines.empty()) return NAN;
  auto mid = cosines.begin() + static_cast<std::ptrdiff_t>(cosines.size() / 2);
  std::nth_element(cosines.begin(), mid, cosines.end());  // the median cosine: the median angle
  return std::acos(std::min(1.0f, *mid)) * 180.0 / M_PI;
}

double growingAngleDeg(const GridIndex& index, double c, const ClusterOptions& opt, const GridNormals& normals) {
  if (!(opt.smoothness_noise_factor > 0.0)) return opt.smoothness_deg;
  const double median = medianNeighbourAngleDeg(index, c, opt, normals);
  if (!std::isfinite(median)) return opt.smoothness_deg;
  return std::clamp(opt.smoothness_noise_factor * median, std::min(opt.smoothness_min_deg, opt.smoothness_deg),
                    opt.smoothness_deg);
}

double estimateTimeScaleOnIndex(const std::vector<const GridIndex*>& indexes, double c0,
                                const ClusterOptions& opt) {
  size_t total = 0;
  for (const GridIndex* ix : indexes) total += ix->size();
  if (total == 0) return 0.0;
  const size_t stride = std::max<size_t>(1, total / 4000);  // about 4000 sampled planes
  double c = c0;
  for (int iter = 0; iter < 4; ++iter) {
    std::vector<double> speeds;
    for (const GridIndex* ix : indexes) {
      for (size_t k = stride / 2; k < ix->size(); k += stride) {
        float n[3], cv = 2.0f;
        if (!ix->normal(static_cast<int>(k), c, opt, n, &cv) || cv > opt.curvature_threshold) continue;
        const double nxy = std::hypot(n[0], n[1]);
        if (nxy > 1e-3) speeds.push_back(c * std::fabs(n[2]) / nxy);
      }
    }
    if (speeds.size() < 20) return iter == 0 ? 0.0 : c;
    auto mid = speeds.begin() + speeds.size() / 2;
    std::nth_element(speeds.begin(), mid, speeds.end());
    const double next = std::clamp(*mid, opt.c_min_px_per_s, opt.c_max_px_per_s);
    const bool converged = std::fabs(next - c) < 0.05 * c;
    c = next;
    if (converged) break;
  }
  return c;
}

}  // namespace celc::detail
