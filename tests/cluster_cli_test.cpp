// `celc cluster` end to end: a real ECD slice (skipped when absent) and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_util.hpp"

namespace {

namespace fs = std::filesystem;

using celc::test::CliRun;

/// Runs a shell command with stderr joined to stdout (cli_util.hpp's runShell).
CliRun runCommand(const std::string& command) { return celc::test::runShell(command + " 2>&1"); }

CliRun runCelc(const std::string& args) { return runCommand(std::string(CELC_BINARY) + " " + args); }

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("celc_cluster_cli_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(ClusterCli, ClustersAnEcdSliceAndDumps) {
  const fs::path slice = fs::path(CELC_SOURCE_DIR "/../shared/data/ecd_slices/shapes_translation/events.txt");
  if (!fs::exists(slice)) GTEST_SKIP() << "shared data absent: " << slice;
  const fs::path dir = tempDir("dump");
  const CliRun r = runCelc("cluster " + slice.string() + " --window-events 15000 --dump " + dir.string() + " -q");
  ASSERT_EQ(r.status, 0) << r.out;
  // Two windows of 15000 events, both with clusters.
  EXPECT_NE(r.out.find("\n0,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n1,"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("no_clusters"), std::string::npos) << r.out;
  for (const char* f : {"window_00000.png", "window_00000.ply", "window_00001.png", "window_00001.ply"})
    EXPECT_GT(fs::file_size(dir / f), 1000u) << f;
  {  // a PNG (libpng): the signature, then IHDR with the image's size, 8-bit RGB
    std::ifstream png(dir / "window_00000.png", std::ios::binary);
    unsigned char head[26] = {};
    png.read(reinterpret_cast<char*>(head), sizeof head);
    const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    EXPECT_TRUE(std::equal(signature, signature + 8, head));
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(head + 12), 4), "IHDR");
    const auto be32 = [&](int at) { return (head[at] << 24) | (head[at + 1] << 16) | (head[at + 2] << 8) | head[at + 3]; };
    EXPECT_GT(be32(16), 100);  // width [px]: x-y view and x-t view side by side
    EXPECT_GT(be32(20), 100);  // height [px]
    EXPECT_EQ(head[24], 8);    // bit depth
    EXPECT_EQ(head[25], 2);    // colour type RGB
  }
  std::ifstream ply(dir / "window_00000.ply");
  std::string line;
  int vertices = -1, rows = 0, labelled = 0;
  bool header = true;
  while (std::getline(ply, line)) {
    if (header) {
      if (line.rfind("element vertex ", 0) == 0) vertices = std::stoi(line.substr(15));
      if (line == "end_header") header = false;
      continue;
    }
    std::istringstream in(line);
    double x, y, z, t;
    int label;
    ASSERT_TRUE(in >> x >> y >> z >> t >> label) << line;
    ++rows;
    labelled += label >= 0;
  }
  EXPECT_EQ(vertices, 15000);
  EXPECT_EQ(rows, 15000);
  EXPECT_GT(labelled, 5000);  // shapes_translation: most events lie on swept edges
}

TEST(ClusterCli, MalformedLineNamesFileAndLine) {
  const fs::path dir = tempDir("bad");
  const fs::path f = dir / "events.txt";
  std::ofstream(f) << "# t x y p\r\n0.1 10 20 1\r\n0.2 11 twenty 0\r\n";
  const CliRun r = runCelc("cluster " + f.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find(f.string() + ": line 3:"), std::string::npos) << r.out;  // io reader format
  const CliRun missing = runCelc("cluster " + (dir / "nope.txt").string());
  EXPECT_NE(missing.status, 0);
  EXPECT_NE(missing.out.find("cannot open"), std::string::npos) << missing.out;
}

TEST(ClusterCli, EmptyFileIsNotAnError) {
  const fs::path dir = tempDir("empty");
  const fs::path f = dir / "events.txt";
  std::ofstream(f) << "# nothing\n";
  const CliRun r = runCelc("cluster " + f.string());
  EXPECT_EQ(r.status, 0) << r.out;
}

// PCL is no dependency of the executable: the pcl method's library is loaded
// when options name it, so other runs neither map nor relocate PCL.
TEST(ClusterCli, PclIsLoadedOnlyForThePclMethod) {
  const CliRun deps = runCommand("ldd '" + std::string(CELC_BINARY) + "'");
  ASSERT_EQ(deps.status, 0) << deps.out;
  EXPECT_NE(deps.out.find("libcelc_cluster.so"), std::string::npos) << deps.out;
  EXPECT_EQ(deps.out.find("libpcl"), std::string::npos) << deps.out;
  const std::string sample = std::string(CELC_SOURCE_DIR) + "/data/sample_seq";
  const CliRun pcl = runCelc("cluster '" + sample + "' --method pcl --window-events 20000 --max-windows 1 -q");
  ASSERT_EQ(pcl.status, 0) << pcl.out;
  EXPECT_NE(pcl.out.find(",ok,"), std::string::npos) << pcl.out;  // the PCL grower ran and found clusters
}

}  // namespace
