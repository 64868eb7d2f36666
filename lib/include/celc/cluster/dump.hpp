#pragma once
/// \file dump.hpp
/// Pictures and point clouds of a clustered window, to see what the clustering
/// did (the paper's Fig. 2(b)/(d)).
///  - PNG: left, the x-y image plane; right, space-time as x (horizontal) by t
///    (vertical, downward). Noise events grey, each cluster its own colour; per
///    cluster the fitted start line l1 (white) and end line l3 (black) in the x-y
///    view, and both as segments at their times in the x-t view, in pixel coordinates (fitted to raw pixels: no
///    undistortion, for display only).
///  - PLY (ASCII): one vertex per event with x y [px], z = c (t - t0) [px] (so the
///    cloud has the clustering's aspect), t [s] and the cluster label (-1 = noise);
///    opens in CloudCompare / MeshLab (colour by the scalar field `label`).
#include <string>
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/lines/line_fit.hpp"

namespace celc {

struct ClusterDumpOptions {
  int width = 0, height = 0;  ///< sensor size [px]; 0 = from the events' extent
  int scale = 2;              ///< PNG pixels per sensor pixel
  LineFitOptions lines;       ///< l1 / l3 fitting for the drawing
  std::string title;          ///< drawn at the top left (e.g. "window 3")
};

/// Writes the PNG; throws std::runtime_error naming the file when it cannot be written.
void writeClusterPng(const std::string& path, const std::vector<Event>& events,
                     const ClusterResult& result, const ClusterDumpOptions& options);

/// Writes the ASCII PLY; throws std::runtime_error naming the file when it cannot be written.
void writeClusterPly(const std::string& path, const std::vector<Event>& events,
                     const ClusterResult& result);

}  // namespace celc
