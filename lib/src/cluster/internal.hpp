#pragma once
/// \file internal.hpp
/// Shared pieces of the clustering methods (not a public header).
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "celc/cluster/cluster.hpp"

namespace celc::detail {

/// The events of one group (one polarity, or all events).
struct Group {
  std::vector<float> x, y;      ///< [px]
  std::vector<float> t;         ///< time since the window's first event [s]
  std::vector<int> event_index; ///< index into the caller's event vector
  bool on = true;
  size_t size() const { return x.size(); }
};

/// Region label per point of a group (-1 = none) and the number of regions.
struct Regions {
  std::vector<int> label;
  int count = 0;
  double ms_normals = 0.0;  ///< part of the time spent on normals [ms]
  double smoothness_deg = 0.0;  ///< the angle the growing used [deg]
};

/// Events of a group bucketed per pixel, sorted by time inside each bucket.
/// Neighbours of an event: the events of the (2r+1)^2 pixels around it whose
/// time lies within +-time_radius (a binary search per pixel; at most
/// kMaxPerPixel per pixel, the nearest in time).
class GridIndex {
 public:
  static constexpr int kMaxPerPixel = 8;
  struct Cell {
    float t;         ///< [s] since t0
    int16_t x, y;    ///< pixel relative to the group's bounding box
  };
  explicit GridIndex(const Group& g);
  size_t size() const { return cells_.size(); }
  int point(int k) const { return point_[k]; }  ///< group index of bucket position k
  const Cell& cell(int k) const { return cells_[k]; }

  template <class F>
  void forNeighbours(int k, int r, float time_radius, F&& f) const {
    const Cell& c0 = cells_[k];
    const Cell* base = cells_.data();
    auto less_t = [](const Cell& a, float t) { return a.t < t; };
    auto t_less = [](float t, const Cell& a) { return t < a.t; };
    const int ylo = std::max(0, c0.y - r), yhi = std::min(h_ - 1, c0.y + r);
    const int xlo = std::max(0, c0.x - r), xhi = std::min(w_ - 1, c0.x + r);
    for (int y = ylo; y <= yhi; ++y) {
      const int* row = &start_[static_cast<size_t>(y) * w_];
      for (int x = xlo; x <= xhi; ++x) {
        const int b = row[x], e = row[x + 1];
        if (b == e) continue;
        const Cell* lo = std::lower_bound(base + b, base + e, c0.t - time_radius, less_t);
        const Cell* hi = std::upper_bound(lo, base + e, c0.t + time_radius, t_less);
        if (hi - lo > kMaxPerPixel) {  // keep the ones nearest in time (hot pixels)
          const Cell* mid = std::lower_bound(lo, hi, c0.t, less_t);
          lo = std::max(lo, mid - kMaxPerPixel / 2);
          hi = std::min(hi, lo + kMaxPerPixel);
        }
        for (const Cell* q = lo; q < hi; ++q) f(static_cast<int>(q - base));
      }
    }
  }

  /// Calls f(k, j) once for every unordered pair of neighbours k < j (bucket
  /// positions), pixel by pixel with sliding time windows (two pointers per
  /// neighbouring pixel that comes at or after k's pixel), at most
  /// kMaxPerPixel partners j per pixel (the earliest in the window).
  /// Events k with active(k) false get no pairs (their windows still slide).
  template <class A, class F>
  void sweepPairs(int r, double time_radius, A&& active, F&& f) const {
    struct Nb {
      int lo, hi, end;
    };
    std::vector<Nb> nb;
    for (int p = 0; p < w_ * h_; ++p) {
      const int b = start_[p], e = start_[p + 1];
      if (b == e) continue;
      const int px = p % w_, py = p / w_;
      nb.clear();
      for (int y = std::max(0, py - r); y <= std::min(h_ - 1, py + r); ++y)
        for (int x = std::max(0, px - r); x <= std::min(w_ - 1, px + r); ++x) {
          const int q = y * w_ + x;
          if (q >= p && start_[q] != start_[q + 1]) nb.push_back({start_[q], start_[q], start_[q + 1]});
        }
      for (int k = b; k < e; ++k) {
        const double tk = cells_[k].t;
        const bool act = active(k);
        for (Nb& q : nb) {
          while (q.hi < q.end && cells_[q.hi].t <= tk + time_radius) ++q.hi;
          while (q.lo < q.hi && cells_[q.lo].t < tk - time_radius) ++q.lo;
          if (!act) continue;
          // At most kMaxPerPixel partners per pixel (a hot pixel would be quadratic).
          const int j0 = std::max(q.lo, k + 1), j1 = std::min(q.hi, j0 + kMaxPerPixel);
          for (int j = j0; j < j1; ++j) f(k, j);
        }
      }
    }
  }

  /// Plane normal of the neighbourhood of k in (x, y, c*t) and its curvature
  /// lambda_min / sum(lambda); false when degenerate (too few neighbours, all on
  /// one spot or one line).
  bool normal(int k, double c, const ClusterOptions& opt, float* out_n, float* out_curv) const;

  /// The same for every event at once (no per-pixel cap): one sweep over the
  /// events in time order keeps, per pixel, the run of its bucket within
  /// +-time_radius_px / c of the current event (two counts that only grow), and
  /// the moments of a run are differences of prefix sums over the buckets. Each
  /// event then reads its (2r+1)^2 pixels' runs, without a search. Pixels are
  /// split into `threads` ranges of about equal events; the result does not
  /// depend on `threads`. nrm: 3 per event, curvature 2 where degenerate.
  void allNormals(double c, const ClusterOptions& opt, int threads, float* nrm, float* curv) const;

 private:
  int w_ = 0, h_ = 0;
  std::vector<int> start_;   ///< w*h + 1 bucket starts
  std::vector<int> point_;   ///< bucket position -> group index
  std::vector<Cell> cells_;  ///< in bucket order
  std::vector<int> by_time_; ///< bucket positions in time order (ties: the group's order)
};

/// Plane normal and curvature lambda_min / sum(lambda) of a neighbourhood in
/// (dx, dy, t) from its sums, in this order: count, dx, dy, dx^2, dx dy, dy^2,
/// t, t^2, dx t, dy t [px, s]; c [px/s] scales t. False, curvature 2 and the
/// normal not written, with fewer than min_neighbours events or a degenerate
/// spread (one spot, one line).
bool normalFromSums(const double s[10], double c, int min_neighbours, float* nrm, float* curv);

/// Normals (3 per event) and curvatures (2 = none) in bucket order.
struct GridNormals {
  std::vector<float> nrm, curv;
  double ms = 0.0;  ///< wall time [ms]
};
GridNormals computeGridNormals(const GridIndex& index, double c, const ClusterOptions& opt, int threads);

/// The median angle between the normals of neighbouring low-curvature events
/// [deg] (growing's neighbourhood), over the pairs of about 4000 sampled
/// events: what noise alone gives on one edge's surface, since most pairs lie
/// on one edge. NaN without such pairs.
double medianNeighbourAngleDeg(const GridIndex& index, double c, const ClusterOptions& opt,
                               const GridNormals& normals);

/// The angle the grower uses [deg]: smoothness_deg, or with
/// smoothness_noise_factor > 0 that factor times medianNeighbourAngleDeg,
/// within [min(smoothness_min_deg, smoothness_deg), smoothness_deg].
double growingAngleDeg(const GridIndex& index, double c, const ClusterOptions& opt, const GridNormals& normals);

/// Own region grower on the grid index; normals computed here with `threads`
/// workers unless given (then they are consumed).
Regions growGrid(const GridIndex& index, double c, const ClusterOptions& opt, int threads,
                 GridNormals* normals = nullptr);

/// Reference: pcl::NormalEstimationOMP + pcl::RegionGrowing with a kd-tree,
/// points (x, y, c*t). Defined in libcelc_cluster_pcl.so (pcl/pcl_grower.cpp),
/// which pcl_method.cpp loads on the first use; clusterEvents checks
/// clusterMethodProblem() before any clustering.
Regions growPcl(const Group& g, double c, const ClusterOptions& opt, int threads);

/// Loads the PCL reference method's library (once per process) and returns
/// why it cannot be used: empty when growPcl can be called, else a one-line
/// reason naming the library file.
std::string pclGrowerError();

/// Median normal-flow speed [px/s] of sampled local planes, iterated from c0;
/// 0 when fewer than 20 usable planes.
double estimateTimeScaleOnIndex(const std::vector<const GridIndex*>& indexes, double c0,
                                const ClusterOptions& opt);

}  // namespace celc::detail
