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
namespace {

constexpr int kMaxPerPixel = 8;  // neighbours taken from one pixel at most (hot pixels)

class GridIndex {
 public:
  GridIndex(const Group& g, const ClusterOptions& opt)
      : r_(opt.grid_radius_px), rt_(static_cast<float>(opt.time_radius_px)) {
    const size_t n = g.size();
    if (n == 0) return;
    int xmin = 1 << 30, ymin = 1 << 30, xmax = -(1 << 30), ymax = -(1 << 30);
    std::vector<int> xi(n), yi(n);
    for (size_t i = 0; i < n; ++i) {
      xi[i] = static_cast<int>(std::lround(g.x[i]));
      yi[i] = static_cast<int>(std::lround(g.y[i]));
      xmin = std::min(xmin, xi[i]);
      xmax = std::max(xmax, xi[i]);
      ymin = std::min(ymin, yi[i]);
      ymax = std::max(ymax, yi[i]);
    }
    w_ = xmax - xmin + 1;
    h_ = ymax - ymin + 1;
    // Points in order of increasing z (usually already so).
    std::vector<int> by_time(n);
    std::iota(by_time.begin(), by_time.end(), 0);
    if (!std::is_sorted(g.z.begin(), g.z.end()))
      std::stable_sort(by_time.begin(), by_time.end(),
                       [&](int a, int b) { return g.z[a] < g.z[b]; });
    // Counting sort by pixel, stable: z ascending inside each bucket.
    start_.assign(static_cast<size_t>(w_) * h_ + 1, 0);
    for (size_t i = 0; i < n; ++i) ++start_[pixel(xi[i] - xmin, yi[i] - ymin) + 1];
    for (size_t p = 1; p < start_.size(); ++p) start_[p] += start_[p - 1];
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    point_.resize(n);
    px_.resize(n);
    py_.resize(n);
    z_.resize(n);
    for (int i : by_time) {
      const int k = fill[pixel(xi[i] - xmin, yi[i] - ymin)]++;
      point_[k] = i;
      px_[k] = xi[i] - xmin;
      py_[k] = yi[i] - ymin;
      z_[k] = g.z[i];
    }
  }

  size_t size() const { return z_.size(); }
  int point(int k) const { return point_[k]; }

  /// Calls f(j) for every bucket position j in the neighbourhood of k (k included).
  template <class F>
  void forNeighbours(int k, F&& f) const {
    const int x0 = px_[k], y0 = py_[k];
    const float z = z_[k];
    const float* zb = z_.data();
    for (int y = std::max(0, y0 - r_); y <= std::min(h_ - 1, y0 + r_); ++y) {
      for (int x = std::max(0, x0 - r_); x <= std::min(w_ - 1, x0 + r_); ++x) {
        const size_t p = pixel(x, y);
        const int b = start_[p], e = start_[p + 1];
        if (b == e) continue;
        const float* lo = std::lower_bound(zb + b, zb + e, z - rt_);
        const float* hi = std::upper_bound(lo, zb + e, z + rt_);
        if (hi - lo > kMaxPerPixel) {  // keep the ones nearest in time
          const float* mid = std::lower_bound(lo, hi, z);
          lo = std::max(lo, mid - kMaxPerPixel / 2);
          hi = std::min(hi, lo + kMaxPerPixel);
        }
        for (const float* q = lo; q < hi; ++q) f(static_cast<int>(q - zb));
      }
    }
  }

  /// Plane normal and curvature of the neighbourhood of k; false if degenerate.
  bool normal(int k, int min_neighbours, float* out_n, float* out_curv) const {
    double s[3] = {0, 0, 0}, ss[6] = {0, 0, 0, 0, 0, 0};
    int cnt = 0;
    const float x0 = static_cast<float>(px_[k]), y0 = static_cast<float>(py_[k]), z0 = z_[k];
    forNeighbours(k, [&](int j) {
      const double dx = px_[j] - x0, dy = py_[j] - y0, dz = z_[j] - z0;
      s[0] += dx, s[1] += dy, s[2] += dz;
      ss[0] += dx * dx, ss[1] += dx * dy, ss[2] += dx * dz;
      ss[3] += dy * dy, ss[4] += dy * dz, ss[5] += dz * dz;
      ++cnt;
    });
    if (cnt < min_neighbours) return false;
    const double inv = 1.0 / cnt;
    const double m0 = s[0] * inv, m1 = s[1] * inv, m2 = s[2] * inv;
    Eigen::Matrix3d c;
    c(0, 0) = ss[0] * inv - m0 * m0;
    c(0, 1) = c(1, 0) = ss[1] * inv - m0 * m1;
    c(0, 2) = c(2, 0) = ss[2] * inv - m0 * m2;
    c(1, 1) = ss[3] * inv - m1 * m1;
    c(1, 2) = c(2, 1) = ss[4] * inv - m1 * m2;
    c(2, 2) = ss[5] * inv - m2 * m2;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(c);
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

 private:
  size_t pixel(int x, int y) const { return static_cast<size_t>(y) * w_ + x; }
  int r_ = 2;
  float rt_ = 2.5f;
  int w_ = 0, h_ = 0;
  std::vector<int> start_, point_, px_, py_;
  std::vector<float> z_;
};

template <class F>
void parallelFor(int n, int threads, F&& f) {
  threads = std::max(1, std::min(threads, n / 4096 + 1));
  if (threads == 1) {
    f(0, n);
    return;
  }
  std::vector<std::thread> pool;
  const int chunk = (n + threads - 1) / threads;
  for (int t = 0; t < threads; ++t) {
    const int b = t * chunk, e = std::min(n, b + chunk);
    if (b < e) pool.emplace_back([&f, b, e] { f(b, e); });
  }
  for (auto& th : pool) th.join();
}

}  // namespace

Regions growGrid(const Group& g, const ClusterOptions& opt, int threads) {
  Regions out;
  const int n = static_cast<int>(g.size());
  out.label.assign(n, -1);
  if (n == 0) return out;
  const GridIndex index(g, opt);
  // Normals and curvature in bucket order; curvature 2 marks "no normal".
  std::vector<float> nrm(3 * static_cast<size_t>(n), 0.0f), curv(n, 2.0f);
  parallelFor(n, threads, [&](int b, int e) {
    for (int k = b; k < e; ++k)
      if (!index.normal(k, opt.min_neighbours, &nrm[3 * k], &curv[k])) curv[k] = 2.0f;
  });
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
      index.forNeighbours(cur, [&](int j) {
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

void gridNormals(const Group& g, const ClusterOptions& opt, int stride, std::vector<float>& nx,
                 std::vector<float>& ny, std::vector<float>& nz, std::vector<float>& curvature) {
  nx.clear(), ny.clear(), nz.clear(), curvature.clear();
  if (g.size() == 0) return;
  const GridIndex index(g, opt);
  stride = std::max(1, stride);
  for (size_t k = 0; k < index.size(); k += static_cast<size_t>(stride)) {
    float n[3] = {0, 0, 0}, c = 2.0f;
    if (!index.normal(static_cast<int>(k), opt.min_neighbours, n, &c)) n[0] = n[1] = n[2] = 0.0f;
    nx.push_back(n[0]);
    ny.push_back(n[1]);
    nz.push_back(n[2]);
    curvature.push_back(c);
  }
}

}  // namespace celc::cluster_detail
