#pragma once
/// \file internal.hpp
/// Shared pieces of the clustering methods (not a public header).
#include <vector>

#include "celc/cluster/cluster.hpp"

namespace celc::cluster_detail {

/// The points of one group (one polarity, or all events) in (x, y, c*(t - t0)).
struct Group {
  std::vector<float> x, y, z;   ///< [px]
  std::vector<int> event_index; ///< index into the caller's event vector
  bool on = true;
  size_t size() const { return x.size(); }
};

/// Region label per point of a group (-1 = none) and the number of regions.
struct Regions {
  std::vector<int> label;
  int count = 0;
};

/// Own region grower: neighbours from a (2r+1)^2 pixel window and a c*t range.
/// `threads` workers estimate the normals.
Regions growGrid(const Group& g, const ClusterOptions& opt, int threads);

/// Reference: pcl::NormalEstimationOMP + pcl::RegionGrowing with a kd-tree.
Regions growPcl(const Group& g, const ClusterOptions& opt, int threads);

/// Local plane normals of a group with the grid neighbourhoods (used by the
/// automatic time scale). normal = (0,0,0) where invalid. Only every
/// `stride`-th point is a query point; the output has one entry per query.
void gridNormals(const Group& g, const ClusterOptions& opt, int stride,
                 std::vector<float>& nx, std::vector<float>& ny, std::vector<float>& nz,
                 std::vector<float>& curvature);

}  // namespace celc::cluster_detail
