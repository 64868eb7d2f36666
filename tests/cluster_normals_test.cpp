// The grid grower's per-event normals (GridIndex::allNormals): the planes of
// moving edges, and the very values of a direct search of each event's
// neighbourhood, for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "cluster/internal.hpp"

namespace celc {
namespace {

using detail::GridIndex;

/// Events of straight edges x = x0 + speed t (one per 16 px of the group),
/// spread over y, plus uniform noise, a hot pixel and repeated time stamps.
detail::Group movingEdges(unsigned seed, int events, float speed_px_s) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  detail::Group g;
  auto add = [&](float x, float y, float t) {
    g.x.push_back(std::round(x));
    g.y.push_back(std::round(y));
    g.t.push_back(t);
    g.event_index.push_back(static_cast<int>(g.event_index.size()));
  };
  for (int i = 0; i < events; ++i) {
    const float t = 0.2f * unit(rng);
    const float u = unit(rng);
    if (u < 0.85f) {
      const float x0 = 10.0f + 16.0f * static_cast<float>(static_cast<int>(3.0f * unit(rng)));
      add(x0 + speed_px_s * t, 40.0f * unit(rng), t);
    } else if (u < 0.95f) {
      add(70.0f * unit(rng), 40.0f * unit(rng), t);
    } else {
      add(30.0f, 20.0f, t);  // a hot pixel
    }
    if (i % 50 == 0) add(g.x.back() + 1.0f, g.y.back(), t);  // the same time stamp next door
  }
  // Time order, as a window's events come.
  std::vector<size_t> order(g.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return g.t[a] < g.t[b]; });
  detail::Group sorted;
  for (size_t i : order) {
    sorted.x.push_back(g.x[i]);
    sorted.y.push_back(g.y[i]);
    sorted.t.push_back(g.t[i]);
    sorted.event_index.push_back(static_cast<int>(sorted.event_index.size()));
  }
  return sorted;
}

struct Normals {
  std::vector<float> nrm, curv;
};

Normals sweep(const GridIndex& index, double c, const ClusterOptions& opt, int threads) {
  Normals out{std::vector<float>(3 * index.size(), 0.0f), std::vector<float>(index.size(), 2.0f)};
  index.allNormals(c, opt, threads, out.nrm.data(), out.curv.data());
  return out;
}

/// The same normals by a direct search: per event, a binary search of the
/// time window in each pixel of its (2r+1)^2 neighbourhood, the moments from
/// prefix sums over the buckets, and the reuse of a pixel's last computed
/// normal within normal_reuse_px / c.
Normals direct(const GridIndex& index, double c, const ClusterOptions& opt) {
  const size_t n = index.size();
  std::map<std::pair<int, int>, std::pair<int, int>> bucket;  // (x, y) -> [begin, end) in bucket order
  for (size_t k = 0; k < n; ++k) {
    auto [it, fresh] = bucket.try_emplace({index.cell(k).x, index.cell(k).y}, std::make_pair(int(k), int(k)));
    it->second.second = static_cast<int>(k) + 1;
  }
  std::vector<double> pre_t(n + 1, 0.0), pre_tt(n + 1, 0.0);
  for (size_t k = 0; k < n; ++k) {
    const double t = index.cell(k).t;
    pre_t[k + 1] = pre_t[k] + t;
    pre_tt[k + 1] = pre_tt[k] + t * t;
  }
  const double tau = opt.time_radius_px / c;
  const float reuse_dt = static_cast<float>(opt.normal_reuse_px / c);
  const int r = opt.grid_radius_px;
  Normals out{std::vector<float>(3 * n, 0.0f), std::vector<float>(n, 2.0f)};
  for (const auto& [pixel, range] : bucket) {
    int last = -1;
    for (int k = range.first; k < range.second; ++k) {
      const float tk = index.cell(k).t;
      if (last >= 0 && tk - index.cell(last).t <= reuse_dt) {
        std::copy_n(&out.nrm[3 * size_t(last)], 3, &out.nrm[3 * size_t(k)]);
        out.curv[k] = out.curv[last];
        continue;
      }
      last = k;
      const float t_hi = static_cast<float>(tk + tau), t_lo = static_cast<float>(tk - tau);
      double s[10] = {};
      for (int y = pixel.second - r; y <= pixel.second + r; ++y)
        for (int x = pixel.first - r; x <= pixel.first + r; ++x) {
          const auto found = bucket.find({x, y});
          if (found == bucket.end()) continue;
          int lo = found->second.first, hi = found->second.second;
          while (lo < hi && index.cell(lo).t < t_lo) ++lo;
          int end = lo;
          while (end < hi && index.cell(end).t <= t_hi) ++end;
          const double dx = x - pixel.first, dy = y - pixel.second, m = end - lo;
          const double t = pre_t[end] - pre_t[lo], tt = pre_tt[end] - pre_tt[lo];
          s[0] += m, s[1] += dx * m, s[2] += dy * m, s[3] += dx * dx * m, s[4] += dx * dy * m;
          s[5] += dy * dy * m, s[6] += t, s[7] += tt, s[8] += dx * t, s[9] += dy * t;
        }
      detail::normalFromSums(s, c, opt.min_neighbours, &out.nrm[3 * size_t(k)], &out.curv[k]);
    }
  }
  return out;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Sub-pixel coordinates go to the nearest pixel, halves away from zero (as
// std::lround rounds), also just below a half, where float's 0.5 - 2^-25
// plus 0.5 would round up in float.
TEST(GridIndex, CoordinatesGoToTheNearestPixelHalvesUp) {
  const std::vector<std::pair<float, int>> cases = {
      {0.0f, 0}, {0.49999997f, 0}, {0.5f, 1}, {1.5f, 2}, {2.4999998f, 2}, {2.5f, 3}, {7.75f, 8}, {4095.4f, 4095}};
  detail::Group g;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    g.x.push_back(cases[i].first);
    g.y.push_back(cases[i].first);
    g.t.push_back(0.001f * static_cast<float>(i));
    g.event_index.push_back(static_cast<int>(i));
  }
  const GridIndex index(g);
  ASSERT_EQ(index.size(), cases.size());
  for (std::size_t k = 0; k < index.size(); ++k) {
    const int i = index.point(static_cast<int>(k));
    SCOPED_TRACE("x = y = " + std::to_string(cases[i].first));
    EXPECT_EQ(index.cell(static_cast<int>(k)).x, cases[i].second);  // the box starts at pixel 0
    EXPECT_EQ(index.cell(static_cast<int>(k)).y, cases[i].second);
    EXPECT_EQ(cases[i].second, static_cast<int>(std::lround(cases[i].first)));
  }
}

TEST(GridNormals, TheSweepGivesTheDirectSearchsValuesForAnyThreadCount) {
  const detail::Group g = movingEdges(7, 30000, 150.0f);
  const GridIndex index(g);
  const double c = 150.0;
  for (double reuse : {0.0, 0.25, 1.0}) {
    ClusterOptions opt;
    opt.normal_reuse_px = reuse;
    const Normals want = direct(index, c, opt);
    size_t with_normal = 0;
    for (float k : want.curv) with_normal += k <= 1.0f;
    ASSERT_GT(with_normal, index.size() / 2) << "reuse " << reuse;  // a test of normals, not of their absence
    for (int threads : {1, 2, 3}) {
      const Normals got = sweep(index, c, opt, threads);
      EXPECT_TRUE(sameBits(got.nrm, want.nrm)) << "reuse " << reuse << ", threads " << threads;
      EXPECT_TRUE(sameBits(got.curv, want.curv)) << "reuse " << reuse << ", threads " << threads;
    }
  }
}

TEST(GridNormals, AnEdgesEventsGetTheNormalOfTheSurfaceItSweeps) {
  // x = x0 + v t is the plane x - (v / c) (c t) = x0 in (x, y, c t): normal
  // (1, 0, -v / c) / |.|. Whole pixels blur x by up to 0.5 px over a 5 px
  // neighbourhood, so the median event is within a few degrees of it.
  const float speed = 150.0f;
  const double c = 300.0;
  const detail::Group g = movingEdges(11, 30000, speed);
  const GridIndex index(g);
  ClusterOptions opt;
  const Normals got = sweep(index, c, opt, 2);
  const double kx = 1.0, kz = -speed / c, norm = std::hypot(kx, kz);
  std::vector<double> angles;
  for (size_t k = 0; k < index.size(); ++k) {
    if (!(got.curv[k] < opt.curvature_threshold)) continue;
    const float* m = &got.nrm[3 * k];
    angles.push_back(std::acos(std::min(1.0, std::abs(m[0] * kx + m[2] * kz) / norm)) * 180.0 / M_PI);
  }
  ASSERT_GT(angles.size(), index.size() / 2);
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  EXPECT_LT(angles[angles.size() / 2], 5.0);
}

// The growing's low-curvature events: each region is a connected component of
// the graph whose edges are the pairs sweepPairs gives with both ends below
// the curvature threshold and normals within the growing angle. Found here by
// a breadth-first search over the pairs, against growGrid's union-find (whose
// roots follow the unions it makes pair by pair).
TEST(GridGrowing, LowCurvatureRegionsAreTheComponentsOfSimilarNeighbours) {
  const detail::Group g = movingEdges(13, 30000, 150.0f);
  const GridIndex index(g);
  const double c = 150.0;
  const ClusterOptions opt;
  detail::GridNormals normals = detail::computeGridNormals(index, c, opt, 1);
  const detail::Regions regions = detail::growGrid(index, c, opt, 1, &normals);
  const float cos_thr = static_cast<float>(std::cos(regions.smoothness_deg * M_PI / 180.0));
  const size_t n = index.size();
  auto low = [&](size_t k) { return normals.curv[k] < static_cast<float>(opt.curvature_threshold); };
  std::vector<std::vector<int>> adjacent(n);
  index.sweepPairs(opt.grow_radius_px, opt.grow_time_radius_px / c, [](int) { return true; }, [&](int k, int j) {
    const float* a = &normals.nrm[3 * size_t(k)];
    const float* b = &normals.nrm[3 * size_t(j)];
    if (low(k) && low(j) && std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) >= cos_thr) {
      adjacent[k].push_back(j);
      adjacent[j].push_back(k);
    }
  });
  std::vector<int> component(n, -1);
  int components = 0;
  for (size_t s = 0; s < n; ++s) {
    if (!low(s) || component[s] >= 0) continue;
    std::vector<int> queue{static_cast<int>(s)};
    component[s] = components;
    for (size_t q = 0; q < queue.size(); ++q)
      for (int j : adjacent[queue[q]])
        if (component[j] < 0) component[j] = components, queue.push_back(j);
    ++components;
  }
  ASSERT_GT(components, 3);
  // The same partition: one region per component and one component per region.
  std::map<int, int> region_of_component, component_of_region;
  size_t low_events = 0;
  for (size_t k = 0; k < n; ++k) {
    if (!low(k)) continue;
    ++low_events;
    const int region = regions.label[index.point(k)];
    ASSERT_GE(region, 0) << "event " << k;
    const auto [a, fresh_a] = region_of_component.try_emplace(component[k], region);
    const auto [b, fresh_b] = component_of_region.try_emplace(region, component[k]);
    ASSERT_EQ(a->second, region) << "event " << k;
    ASSERT_EQ(b->second, component[k]) << "event " << k;
  }
  EXPECT_GT(low_events, n / 2);
}

}  // namespace
}  // namespace celc
