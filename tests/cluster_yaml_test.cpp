// The cluster / lines YAML schema: config/cluster.yaml parses to the defaults,
// overrides apply, bad keys and types are reported with file and line.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "celc/cluster/cluster_yaml.hpp"

namespace celc {
namespace {

TEST(ClusterYaml, ShippedConfigEqualsDefaults) {
  std::ifstream in(CELC_SOURCE_DIR "/config/cluster.yaml");
  ASSERT_TRUE(in.good());
  std::stringstream ss;
  ss << in.rdbuf();
  ClusterOptions c;
  c.smoothness_deg = 1.0;  // overwritten by the file
  LineFitOptions l;
  l.min_events = 99;
  applyClusterYaml(ss.str(), "cluster.yaml", c, &l);
  const ClusterOptions d;
  EXPECT_EQ(c.smoothness_deg, d.smoothness_deg);
  EXPECT_EQ(c.curvature_threshold, d.curvature_threshold);
  EXPECT_EQ(c.grid_radius_px, d.grid_radius_px);
  EXPECT_EQ(c.time_radius_px, d.time_radius_px);
  EXPECT_EQ(c.grow_time_radius_px, d.grow_time_radius_px);
  EXPECT_EQ(c.min_cluster_size, d.min_cluster_size);
  EXPECT_EQ(c.min_density_per_px2, d.min_density_per_px2);
  EXPECT_EQ(c.min_time_span_s, d.min_time_span_s);
  EXPECT_EQ(c.pcl_normal_radius_px, d.pcl_normal_radius_px);
  EXPECT_EQ(c.method, d.method);
  EXPECT_EQ(l.min_events, LineFitOptions{}.min_events);
  EXPECT_EQ(l.min_length_px, LineFitOptions{}.min_length_px);
}

TEST(ClusterYaml, OverridesAndErrors) {
  ClusterOptions c;
  applyClusterYaml("cluster:\n  method: pcl\n  c_px_per_s: 250\n  separate_polarity: false\n", "a.yaml", c);
  EXPECT_EQ(c.method, ClusterMethod::Pcl);
  EXPECT_EQ(c.c_px_per_s, 250.0);
  EXPECT_FALSE(c.separate_polarity);
  auto message = [](const std::string& text) {
    ClusterOptions o;
    LineFitOptions l;
    try {
      applyClusterYaml(text, "b.yaml", o, &l);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message("cluster:\n  smoothnes_deg: 5\n"), "b.yaml:2: unknown key 'cluster.smoothnes_deg'");
  EXPECT_EQ(message("cluster:\n  threads: two\n"), "b.yaml:2: 'threads' has the wrong type");
  EXPECT_NE(message("cluster:\n  method: kmeans\n").find("b.yaml:2:"), std::string::npos);
  EXPECT_NE(message("cluster:\n  smoothness_deg: 200\n").find("smoothness_deg must be"), std::string::npos);
  EXPECT_NE(message("lines:\n  min_events: 1\n").find("lines: min_events"), std::string::npos);
  EXPECT_NE(message("cluster: [1, 2\n").find("b.yaml:"), std::string::npos);
  // A failed apply leaves the options untouched.
  ClusterOptions o;
  EXPECT_THROW(applyClusterYaml("cluster:\n  c_px_per_s: 10\n  bogus: 1\n", "c.yaml", o), std::runtime_error);
  EXPECT_EQ(o.c_px_per_s, ClusterOptions{}.c_px_per_s);
}

}  // namespace
}  // namespace celc
