// Fast region grower: events bucketed per pixel and sorted by c*t inside each
// bucket, so the neighbours of an event are the events of the (2r+1)^2 pixels
// around it whose c*t lies within +-time_radius_px (a binary search per pixel).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <thread>

#include "cluster/internal.hpp"

namespace celc::cluster_detail {

GridIndex::GridIndex(const Group& g) {
  const size_t n = g.size();
  if (n == 0) return;
  int xmin = 1 << 30, ymin = 1 << 30, xmax = -(1 << 30), ymax = -(1 << 30);
  std::vector<int> pix(n);
  for (size_t i = 0; i < n; ++i) {
    const int xi = static_cast<int>(std::lround(g.x[i])), yi = static_cast<int>(std::lround(g.y[i]));
    xmin = std::min(xmin, xi), xmax = std::max(xmax, xi);
    ymin = std::min(ymin, yi), ymax = std::max(ymax, yi);
  }
  w_ = xmax - xmin + 1;
  h_ = ymax - ymin + 1;
  for (size_t i = 0; i < n; ++i)
    pix[i] = (static_cast<int>(std::lround(g.y[i])) - ymin) * w_ +
             static_cast<int>(std::lround(g.x[i])) - xmin;
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
  for (int i : by_time) {
    const int k = fill[pix[i]]++;
    point_[k] = i;
    cells_[k] = {g.t[i], static_cast<int16_t>(pix[i] % w_), static_cast<int16_t>(pix[i] / w_)};
  }
}

namespace {

/// Normal (eigenvector of the smallest eigenvalue) and curvature from the
/// central moments of a neighbourhood; false when degenerate.
bool normalFromCovariance(const Eigen::Matrix3d& cov, float* out_n, float* out_curv) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(cov);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  const double sum = ev.sum();
  // Degenerate: all points on one spot or one line (e.g. a single hot pixel).
  if (!(sum > 1e-9) || ev(1) < 1e-3 * sum || ev(1) < 1e-4) return false;
  const Eigen::Vector3d nrm = es.eigenvectors().col(0);
  out_n[0] = static_cast<float>(nrm(0));
  out_n[1] = static_cast<float>(nrm(1));
  out_n[2] = static_cast<float>(nrm(2));
  *out_curv = static_cast<float>(std::max(0.0, ev(0)) / sum);
  return true;
}

}  // namespace

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
  const int n_pix = w_ * h_;
  auto work = [&](int p_begin, int p_end) {
    struct Nb {
      int lo, hi, end;
      double dx, dy;
    };
    std::vector<Nb> nb;
    nb.reserve((2 * r + 1) * (2 * r + 1));
    for (int p = p_begin; p < p_end; ++p) {
      const int b = start_[p], e = start_[p + 1];
      if (b == e) continue;
      const int px = p % w_, py = p / w_;
      nb.clear();
      for (int y = std::max(0, py - r); y <= std::min(h_ - 1, py + r); ++y)
        for (int x = std::max(0, px - r); x <= std::min(w_ - 1, px + r); ++x) {
          const int q = y * w_ + x;
          if (start_[q] != start_[q + 1])
            nb.push_back({start_[q], start_[q], start_[q + 1], double(x - px), double(y - py)});
        }
      // Running sums over the events inside the windows: count, dx, dy, dx^2,
      // dx dy, dy^2, t, t^2, dx t, dy t (t relative to this pixel's first event).
      double S[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
      const double tb = cells_[b].t;
      for (int k = b; k < e; ++k) {
        const double tk = cells_[k].t;
        for (Nb& q : nb) {
          while (q.hi < q.end && cells_[q.hi].t <= tk + tau) {
            const double t = cells_[q.hi].t - tb;
            S[0] += 1, S[1] += q.dx, S[2] += q.dy, S[3] += q.dx * q.dx, S[4] += q.dx * q.dy;
            S[5] += q.dy * q.dy, S[6] += t, S[7] += t * t, S[8] += q.dx * t, S[9] += q.dy * t;
            ++q.hi;
          }
          while (q.lo < q.hi && cells_[q.lo].t < tk - tau) {
            const double t = cells_[q.lo].t - tb;
            S[0] -= 1, S[1] -= q.dx, S[2] -= q.dy, S[3] -= q.dx * q.dx, S[4] -= q.dx * q.dy;
            S[5] -= q.dy * q.dy, S[6] -= t, S[7] -= t * t, S[8] -= q.dx * t, S[9] -= q.dy * t;
            ++q.lo;
          }
        }
        curv[k] = 2.0f;
        const double n = S[0];
        if (n < opt.min_neighbours) continue;
        // Central moments of (dx, dy, c t).
        const double mx = S[1] / n, my = S[2] / n, mt = S[6] / n;
        Eigen::Matrix3d cov;
        cov(0, 0) = S[3] / n - mx * mx;
        cov(0, 1) = cov(1, 0) = S[4] / n - mx * my;
        cov(1, 1) = S[5] / n - my * my;
        cov(0, 2) = cov(2, 0) = c * (S[8] / n - mx * mt);
        cov(1, 2) = cov(2, 1) = c * (S[9] / n - my * mt);
        cov(2, 2) = c * c * (S[7] / n - mt * mt);
        if (!normalFromCovariance(cov, &nrm[3 * static_cast<size_t>(k)], &curv[k])) curv[k] = 2.0f;
      }
    }
  };
  threads = std::max(1, std::min(threads, static_cast<int>(size() / 4096) + 1));
  if (threads == 1) {
    work(0, n_pix);
    return;
  }
  // Split the pixels so that each worker gets about the same number of events.
  std::vector<std::thread> pool;
  int p0 = 0;
  for (int t = 0; t < threads; ++t) {
    const size_t target = size() * static_cast<size_t>(t + 1) / static_cast<size_t>(threads);
    int p1 = t + 1 == threads
                 ? n_pix
                 : static_cast<int>(std::upper_bound(start_.begin(), start_.end(), static_cast<int>(target)) -
                                    start_.begin()) - 1;
    p1 = std::clamp(p1, p0, n_pix);
    pool.emplace_back(work, p0, p1);
    p0 = p1;
  }
  for (auto& th : pool) th.join();
}

Regions growGrid(const GridIndex& index, double c, const ClusterOptions& opt, int threads) {
  Regions out;
  const int n = static_cast<int>(index.size());
  out.label.assign(n, -1);
  if (n == 0) return out;
  // Normals and curvature in bucket order; curvature 2 marks "no normal".
  std::vector<float> nrm(3 * static_cast<size_t>(n), 0.0f), curv(n, 2.0f);
  index.allNormals(c, opt, threads, nrm.data(), curv.data());
  // Seeds by increasing curvature: counting sort on the quantised curvature
  // (curvature of a valid normal is in [0, 1/3]).
  constexpr int kBins = 4096;
  std::vector<int> bin_start(kBins + 1, 0);
  auto binOf = [&](float c) { return std::min(kBins - 1, static_cast<int>(c * 3.0f * kBins)); };
  int n_valid = 0;
  for (int k = 0; k < n; ++k)
    if (curv[k] <= 1.0f) ++bin_start[binOf(curv[k]) + 1], ++n_valid;
  for (int b = 0; b < kBins; ++b) bin_start[b + 1] += bin_start[b];
  std::vector<int> seeds(n_valid);
  for (int k = 0; k < n; ++k)
    if (curv[k] <= 1.0f) seeds[bin_start[binOf(curv[k])]++] = k;

  const float cos_thr = static_cast<float>(std::cos(opt.smoothness_deg * M_PI / 180.0));
  const float curv_thr = static_cast<float>(opt.curvature_threshold);
  const float grow_time_radius = static_cast<float>(opt.time_radius_px / c);
  std::vector<int> lab(n, -1), queue;
  queue.reserve(1024);
  int region = 0;
  for (int s : seeds) {
    if (lab[s] != -1) continue;
    lab[s] = region;
    queue.clear();
    queue.push_back(s);
    for (size_t qi = 0; qi < queue.size(); ++qi) {
      const int cur = queue[qi];
      const float* nc = &nrm[3 * cur];
      index.forNeighbours(cur, opt.grow_radius_px, grow_time_radius, [&](int j) {
        if (lab[j] != -1 || curv[j] > 1.0f) return;
        const float* nj = &nrm[3 * j];
        if (std::fabs(nc[0] * nj[0] + nc[1] * nj[1] + nc[2] * nj[2]) < cos_thr) return;
        lab[j] = region;
        if (curv[j] < curv_thr) queue.push_back(j);
      });
    }
    ++region;
  }
  for (int k = 0; k < n; ++k) out.label[index.point(k)] = lab[k];
  out.count = region;
  return out;
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

}  // namespace celc::cluster_detail
