// The schema of the clustering options (core/fields.hpp; docs/clustering.md).
#include "celc/cluster/cluster.hpp"
#include "celc/cluster/to_observations.hpp"

namespace celc {

void describe(FieldVisitor& v, ClusterOptions& o) {
  v.enumeration({"method", "", "grid: own region grower (fast); pcl: PCL region growing"}, o.method,
                {ClusterMethod::Grid, ClusterMethod::Pcl});
  v.field({"c_px_per_s", "px/s", "time scale of (x, y, c*t); 0 = estimated per window", atLeast(0)}, o.c_px_per_s);
  v.field({"c_speed_factor", "", "automatic c = this factor x the median normal-flow speed", within(0.1, 100)}, o.c_speed_factor);
  v.field({"c_min_px_per_s", "px/s", "lower clamp of the estimated time scale", above(0)}, o.c_min_px_per_s);
  v.field({"c_max_px_per_s", "px/s", "upper clamp of the estimated time scale", above(0)}, o.c_max_px_per_s);
  v.field({"separate_polarity", "", "cluster ON and OFF events separately (paper)"}, o.separate_polarity);
  v.field({"derotate", "",
           "celc run: cluster the events turned back by the gyro's rotation to the window's middle (an edge "
           "sweeping across the image stays one slowly moving line); false = as recorded (the parallax probes "
           "and later stages always use the recorded events)"},
          o.derotate);
  v.field({"neighbours", "events", "pcl: k nearest neighbours", within(3, 1000)}, o.neighbours);
  v.field({"pcl_normal_radius_px", "px", "pcl: normals from this radius in (x, y, c*t); 0 = k nearest", within(0, 50)},
          o.pcl_normal_radius_px);
  v.field({"grid_radius_px", "px", "grid: normals from a (2r+1)^2 pixel window", within(1, 5)}, o.grid_radius_px);
  v.field({"grow_radius_px", "px", "grid: growing visits a (2r+1)^2 pixel window", within(1, 5)}, o.grow_radius_px);
  v.field({"time_radius_px", "px", "grid, normals: time range in c*t units", withinAbove(0, 100)}, o.time_radius_px);
  v.field({"grow_time_radius_px", "px", "grid, growing: time range in c*t units", withinAbove(0, 100)}, o.grow_time_radius_px);
  v.field({"normal_reuse_px", "px", "grid: reuse a pixel's normal within this c*t distance (0 = never)", within(0, 2)},
          o.normal_reuse_px);
  v.field({"min_neighbours", "events", "grid: fewer neighbours -> no normal", atLeast(3)}, o.min_neighbours);
  v.field({"smoothness_deg", "deg", "max angle between neighbouring normals", withinAbove(0, 90)}, o.smoothness_deg);
  v.field({"smoothness_noise_factor", "-",
           "grid: the angle is this times the window's median angle between neighbouring normals, within "
           "[smoothness_min_deg, smoothness_deg] (0 = smoothness_deg)", atLeast(0)},
          o.smoothness_noise_factor);
  v.field({"smoothness_min_deg", "deg", "grid: ... at least this", withinAbove(0, 90)}, o.smoothness_min_deg);
  v.field({"curvature_threshold", "-", "max curvature of a point grown from (0..1/3)", withinAbove(0, 1)}, o.curvature_threshold);
  v.field({"min_cluster_size", "events", "smaller clusters are dropped", atLeast(3)}, o.min_cluster_size);
  v.field({"max_cluster_size", "events", "larger regions are not clusters"}, o.max_cluster_size);
  v.field({"max_plane_rms_px", "px", "max RMS distance to the cluster's plane", above(0)}, o.max_plane_rms_px);
  v.field({"ransac_threshold_px", "px", "inlier distance when splitting a region", above(0)}, o.ransac_threshold_px);
  v.field({"max_split", "", "planes extracted from one region at most", within(1, 64)}, o.max_split);
  v.field({"line_split_px", "px",
           "cut each cluster to the events one moving line explains within this distance (sequential RANSAC); "
           "0 = not cut", within(0, 50)},
          o.line_split_px);
  v.field({"line_scale_ratio", "",
           "after the cut, drop a part whose median distance to its moving line exceeds this many times the "
           "window's (event-weighted median part, at least 0.25 px): two edges one line fits, at a corner; needs "
           "6 parts; 0 = keep every part, else >= 1", within(0, 100)},
          o.line_scale_ratio);
  v.field({"recover_cell_px", "px",
           "after the cut, the events in no cluster are grouped where they touch on a grid of this cell in "
           "(x, y, c t) and cut to moving lines the same way; lines of min_cluster_size events whose median "
           "distance is at most twice the window's become clusters; 0 = not recovered, else >= 1",
           within(0, 32)},
          o.recover_cell_px);
  v.field({"motion_reassign_px", "px",
           "after a first solve, each event joins the one cluster whose line under the window's estimated motion "
           "passes within this distance (kept where the first method still answers and the window's cost per "
           "event falls); 0 = not redrawn", within(0, 50)},
          o.motion_reassign_px);
  v.field({"motion_redraw_rounds", "",
           "redraws at most, each from the answer on the last kept clusters (stops at the first not kept)", within(1, 10)},
          o.motion_redraw_rounds);
  v.field({"motion_join_px", "px",
           "clusters both within this median distance of their joint line under the estimated motion join "
           "(fragments of one edge); 0 = none join", within(0, 50)},
          o.motion_join_px);
  v.field({"min_time_span_s", "s", "shortest cluster duration", atLeast(0)}, o.min_time_span_s);
  v.field({"min_extent_px", "px", "smallest spatial extent", atLeast(0)}, o.min_extent_px);
  v.field({"min_density_per_px2", "1/px^2", "fewest events per px^2 of the plane", atLeast(0)}, o.min_density_per_px2);
  v.field({"threads", "", "worker threads inside one window: its clustering, lines, redraws and methods",
           within(1, 256)},
          o.threads);
  v.field({"seed", "", "RANSAC seed"}, o.seed);
}

void describe(FieldVisitor& v, ObservationOptions& o) {
  v.field({"min_events", "events", "clusters with fewer usable events are skipped", atLeast(2)}, o.min_events);
  v.field({"merge_px", "px",
           "clusters within this median distance of each other's moving line become one (fragments of one edge); "
           "0 = off",
           within(0, 20)},
          o.merge_px);
}

}  // namespace celc
