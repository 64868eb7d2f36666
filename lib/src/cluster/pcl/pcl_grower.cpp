// Reference method: PCL normals (k nearest neighbours from a kd-tree) and
// pcl::RegionGrowing with the same criteria as the grid grower. Built as its
// own library, libcelc_cluster_pcl.so, which libcelc_cluster loads on the
// method's first use (pcl_method.cpp): only runs that ask for it map PCL.
#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/radius_outlier_removal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>

#include <algorithm>
#include <cmath>

#include "cluster/internal.hpp"

namespace celc::detail {

namespace {

Regions growWithPcl(const Group& g, double c, const ClusterOptions& opt, int threads) {
  Regions out;
  const size_t n = g.size();
  out.label.assign(n, -1);
  if (n < 3) return out;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->resize(n);
  for (size_t i = 0; i < n; ++i) (*cloud)[i] = pcl::PointXYZ(g.x[i], g.y[i], static_cast<float>(c * g.t[i]));
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(static_cast<unsigned>(threads));
  ne.setInputCloud(cloud);
  ne.setSearchMethod(tree);
  if (opt.pcl_normal_radius_px > 0.0)
    ne.setRadiusSearch(opt.pcl_normal_radius_px);
  else
    ne.setKSearch(opt.neighbours);
  ne.compute(*normals);

  // Isolated events (fewer than min_neighbours within the normal radius) take no
  // part: their normals are noise and kNN growth would bridge lines through them.
  pcl::IndicesPtr kept(new pcl::Indices);
  pcl::RadiusOutlierRemoval<pcl::PointXYZ> ror;
  ror.setInputCloud(cloud);
  ror.setRadiusSearch(opt.pcl_normal_radius_px > 0.0 ? opt.pcl_normal_radius_px : 2.0 * opt.grid_radius_px);
  ror.setMinNeighborsInRadius(opt.min_neighbours);
  ror.filter(*kept);
  // Too few events left to grow a cluster: PCL's region growing does not
  // accept empty indices (it dereferences an empty kd-tree), so stop here.
  if (kept->size() < std::max<size_t>(3, static_cast<size_t>(opt.min_cluster_size))) return out;

  pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> rg;
  rg.setIndices(kept);
  rg.setMinClusterSize(static_cast<pcl::uindex_t>(opt.min_cluster_size));
  rg.setMaxClusterSize(static_cast<pcl::uindex_t>(opt.max_cluster_size));
  rg.setSearchMethod(tree);
  rg.setNumberOfNeighbours(static_cast<unsigned>(opt.neighbours));
  rg.setInputCloud(cloud);
  rg.setInputNormals(normals);
  rg.setSmoothnessThreshold(static_cast<float>(opt.smoothness_deg * M_PI / 180.0));
  rg.setCurvatureThreshold(static_cast<float>(opt.curvature_threshold));
  std::vector<pcl::PointIndices> clusters;
  rg.extract(clusters);
  int id = 0;
  for (const auto& c : clusters) {
    for (const auto i : c.indices)
      if (i >= 0 && static_cast<size_t>(i) < n) out.label[i] = id;
    ++id;
  }
  out.count = id;
  return out;
}

}  // namespace

}  // namespace celc::detail

/// The library's one entry point: the address of the grower, a function of
/// type celc::detail::PclGrowFunction (pcl_method.cpp looks it up by this
/// unmangled name).
extern "C" __attribute__((visibility("default"))) void* celc_cluster_pcl_grower() {
  return reinterpret_cast<void*>(&celc::detail::growWithPcl);
}
