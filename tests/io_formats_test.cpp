// One sequence in every input format gives the same windows.csv rows: the
// text directory `celc synth` wrote, AEDAT 4.0 (the project's writer), a ROS
// bag with lz4 chunks (camera and ground truth from the bag) and HDF5 in the
// DSEC and MVSEC layouts (fixtures: tests/fixtures/make_fixtures.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "celc/io/event_reader.hpp"
#include "celc/io/text_io.hpp"
#include "celc/io/writers.hpp"
#include "cli_util.hpp"
#include "io_fixtures.hpp"

namespace fs = std::filesystem;
using namespace celc;
using celc::test::fixture;
using celc::test::fixtureSequence;

namespace {
// windows.csv lines without the runtime_ms column (the 16th), which differs run to run.
std::vector<std::string> rowsWithoutRuntime(const fs::path& csv) {
  std::istringstream in(celc::test::readAll(csv));
  std::vector<std::string> rows;
  for (std::string l; std::getline(in, l);) {
    std::size_t pos = 0;
    for (int i = 0; i < 15 && pos != std::string::npos; ++i) pos = l.find(',', pos + 1);
    if (pos == std::string::npos) {
      rows.push_back(l);
      continue;
    }
    const std::size_t end = l.find(',', pos + 1);
    rows.push_back(l.substr(0, pos) + (end == std::string::npos ? std::string() : l.substr(end)));
  }
  return rows;
}
const std::string kFast = " -q --threads 2 --window-events 15000 --set windows.t_end=0.12 ";
}  // namespace

TEST(IoFormats, SameSequenceGivesTheSameWindowsRowsInEveryFormat) {
  CELC_REQUIRE_IO_FIXTURES();
  const fs::path d = celc::test::freshTempDir("io_formats");
  const std::string seq = fixtureSequence();
  {
    auto text = openEventSource(seq);
    writeAedat4((d / "seq.aedat4").string(), readAllEvents(*text), {}, 346, 260, Aedat4Compression::Lz4);
  }
  const std::string side = " --calib '" + seq + "/calib.yaml' --groundtruth '" + seq + "/groundtruth.txt' ";
  struct Case {
    std::string name, args;
  };
  const std::vector<Case> cases = {
      {"text", "'" + seq + "' --truth-labels none"},  // the other formats carry no labels.txt
      {"aedat4", "'" + (d / "seq.aedat4").string() + "'" + side + "--imu '" + seq + "/imu.txt'"},
      {"bag", "'" + fixture("seq_lz4.bag") + "'"},  // camera, IMU and poses from the bag
      {"bag_topics", "'" + fixture("seq_bz2.bag") + "' --topic-events /dvs/events --topic-imu /dvs/imu"},
      {"dsec", "'" + fixture("seq_dsec.h5") + "'" + side + "--imu '" + seq + "/imu.txt'"},
      {"mvsec", "'" + fixture("seq_mvsec.h5") + "'" + side},  // IMU from the file
  };
  std::vector<std::string> reference;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const auto r = celc::test::runCelc("run " + c.args + " -o '" + (d / c.name).string() + "'" + kFast, d);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto rows = rowsWithoutRuntime(d / c.name / "windows.csv");
    ASSERT_GT(rows.size(), 4u);
    if (reference.empty()) {
      reference = rows;
      continue;
    }
    ASSERT_EQ(rows.size(), reference.size());
    for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i], reference[i]) << "row " << i;
  }
  // The bag run found its ground truth: metrics are filled.
  EXPECT_NE(reference[1].find(",ok,"), std::string::npos) << reference[1];
  // `celc batch`: a bag entry, its topic named by the YAML key input.topic_events.
  std::ofstream(d / "batch.yaml") << "sequences:\n  - {label: bag, path: '" << fixture("seq_lz4.bag")
                                  << "', config: {input: {topic_events: /dvs/events}}}\n";
  const auto b = celc::test::runCelc("batch '" + (d / "batch.yaml").string() + "' -o '" + (d / "batch").string() +
                                         "'" + kFast,
                                     d);
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(rowsWithoutRuntime(d / "batch" / "bag" / "windows.csv"), reference);
  std::ofstream(d / "bad.yaml") << "sequences:\n  - {label: bag, path: '" << fixture("seq_lz4.bag")
                                << "', config: {input: {topic_events: /dvs/imu}}}\n";
  const auto bad = celc::test::runCelc("batch '" + (d / "bad.yaml").string() + "' -o '" + (d / "bad").string() +
                                           "'" + kFast,
                                       d);
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("seq_lz4.bag: topic /dvs/imu: unknown message type sensor_msgs/Imu"), std::string::npos)
      << bad.err;
  fs::remove_all(d);
}

TEST(IoFormats, InfoListsBagTopicsTypesCountsRates) {
  CELC_REQUIRE_IO_FIXTURES();
  const fs::path d = celc::test::freshTempDir("io_info");
  const auto r = celc::test::runCelc("info '" + fixture("seq_lz4.bag") + "'", d);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("format:        ROS bag"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sensor:        346 x 260 px"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("topic /dvs/events: dvs_msgs/EventArray, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("topic /dvs/imu: sensor_msgs/Imu, 301 messages, 1000 Hz (IMU)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("topic /optitrack/pose: geometry_msgs/PoseStamped, 61 messages"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("camera info on /dvs/camera_info: 346x260"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ground-truth poses: 61"), std::string::npos) << r.out;
  const auto bad = celc::test::runCelc("info '" + fixture("bad_truncated.bag") + "'", d);
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("bad_truncated.bag: byte 13"), std::string::npos) << bad.err;
  fs::remove_all(d);
}
