// ROS bag input: the fixtures of tests/fixtures/make_fixtures.cpp hold the
// sequence `celc synth` rendered as text, so every bag must read back as the
// text does, bit for bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "celc/io/calibration.hpp"
#include "celc/io/event_reader.hpp"
#include "celc/io/text_io.hpp"
#include "bag12_writer.hpp"
#include "io_fixtures.hpp"
#include "io_test_util.hpp"

namespace fs = std::filesystem;
using namespace celc;
using celc::test::fixture;
using celc::test::fixtureSequence;
using celc::test::ioErrorOf;

namespace {
bool hasNote(const EventReader& r, const std::string& part) {
  for (const auto& n : r.notes())
    if (n.find(part) != std::string::npos) return true;
  return false;
}
}  // namespace

// Every chunk compression (the parameter: none, bz2, lz4) reads as the text.
class IoRosbagCompression : public ::testing::TestWithParam<const char*> {};

TEST_P(IoRosbagCompression, EveryCompressionReadsAsTheText) {
  CELC_REQUIRE_IO_FIXTURES();
  const auto text = celc::test::fixtureTextEvents();
  ASSERT_GT(text.size(), 10000u);
  const auto imu_text = readImuText(fixtureSequence() + "/imu.txt");
  const auto poses_text = readPosesText(fixtureSequence() + "/groundtruth.txt");
  {
    const std::string name = std::string("seq_") + GetParam() + ".bag";
    SCOPED_TRACE(name);
    auto r = openEventSource(fixture(name));
    EXPECT_EQ(r->format(), Format::RosBag);
    EXPECT_EQ(r->width(), 346);
    EXPECT_EQ(r->height(), 260);
    celc::test::expectSameEvents(readAllEvents(*r), text);
    EXPECT_EQ(r->warnings().total(), 0u);
    const auto imu = r->readImu();
    ASSERT_EQ(imu.size(), imu_text.size());
    for (std::size_t i = 0; i < imu.size(); ++i) {
      EXPECT_EQ(imu[i].t, imu_text[i].t);
      EXPECT_EQ(imu[i].gyro, imu_text[i].gyro);
      EXPECT_EQ(imu[i].accel, imu_text[i].accel);
    }
    const auto poses = r->readPoses();
    ASSERT_EQ(poses.size(), poses_text.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(poses[i].t, poses_text[i].t);
      EXPECT_EQ(poses[i].position, poses_text[i].position);
      EXPECT_EQ(poses[i].orientation.coeffs(), poses_text[i].orientation.coeffs());
    }
    EXPECT_TRUE(hasNote(*r, "topic /dvs/events: dvs_msgs/EventArray")) << r->notes().front();
    EXPECT_TRUE(hasNote(*r, "topic /dvs/imu: sensor_msgs/Imu"));
    EXPECT_TRUE(hasNote(*r, "(ground truth)"));
    if (std::string(GetParam()) == "lz4") {
      EXPECT_TRUE(hasNote(*r, " lz4"));
    }
  }
}
INSTANTIATE_TEST_SUITE_P(Chunks, IoRosbagCompression, ::testing::Values("none", "bz2", "lz4"),
                         [](const ::testing::TestParamInfo<const char*>& i) { return std::string(i.param); });

// Batches of every size give the same stream (a batch may end inside a message).
TEST(IoRosbag, BatchesSplitMessagesAnywhere) {
  CELC_REQUIRE_IO_FIXTURES();
  const auto text = celc::test::fixtureTextEvents();
  for (std::size_t batch : {1u, 7u, 1499u, 1500u, 4096u}) {
    auto r = openEventSource(fixture("seq_lz4.bag"));
    std::vector<Event> all, b;
    while (r->next(b, batch)) {
      ASSERT_LE(b.size(), batch);
      all.insert(all.end(), b.begin(), b.end());
    }
    celc::test::expectSameEvents(all, text);
  }
}

TEST(IoRosbag, OdometryGroundTruthAndPosesThroughTheTextEntryPoint) {
  CELC_REQUIRE_IO_FIXTURES();
  const auto poses_text = readPosesText(fixtureSequence() + "/groundtruth.txt");
  // readPosesText given a bag: the bag's pose topic (what `celc run BAG` uses).
  for (const char* name : {"seq_odom.bag", "seq_none.bag"}) {
    const auto poses = readPosesText(fixture(name));
    ASSERT_EQ(poses.size(), poses_text.size()) << name;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(poses[i].t, poses_text[i].t);
      EXPECT_EQ(poses[i].position, poses_text[i].position);
      EXPECT_EQ(poses[i].orientation.coeffs(), poses_text[i].orientation.coeffs());
    }
  }
}

TEST(IoRosbag, CameraInfoGivesTheCalibration) {
  CELC_REQUIRE_IO_FIXTURES();
  const Calibration yaml = loadCalibration(fixtureSequence() + "/calib.yaml");
  const Calibration bag = loadCalibration(fixture("seq_lz4.bag"));
  EXPECT_EQ(bag.camera.width, yaml.camera.width);
  EXPECT_EQ(bag.camera.height, yaml.camera.height);
  EXPECT_EQ(bag.camera.fx, yaml.camera.fx);
  EXPECT_EQ(bag.camera.fy, yaml.camera.fy);
  EXPECT_EQ(bag.camera.cx, yaml.camera.cx);
  EXPECT_EQ(bag.camera.cy, yaml.camera.cy);
  EXPECT_EQ(bag.camera.distortion, yaml.camera.distortion);
  EXPECT_EQ(bag.camera.coeffs, yaml.camera.coeffs);
}

TEST(IoRosbag, TopicsFoundByTypeOrNamed) {
  CELC_REQUIRE_IO_FIXTURES();
  ReaderOptions o;
  o.topic_events = "/dvs/events";
  o.topic_imu = "/dvs/imu";
  o.topic_pose = "/optitrack/pose";
  auto r = openEventSource(fixture("seq_none.bag"), o);
  EXPECT_EQ(readAllEvents(*r).size(), celc::test::fixtureTextEvents().size());
  o.topic_events = "/nowhere";
  std::string m = ioErrorOf([&] { openEventSource(fixture("seq_none.bag"), o); });
  EXPECT_NE(m.find("seq_none.bag: no topic /nowhere (input.topic_events)"), std::string::npos) << m;
  EXPECT_NE(m.find("/dvs/events (dvs_msgs/EventArray)"), std::string::npos) << m;
  o.topic_events = "/dvs/imu";
  m = ioErrorOf([&] { openEventSource(fixture("seq_none.bag"), o); });
  EXPECT_NE(m.find("topic /dvs/imu: unknown message type sensor_msgs/Imu for the events topic"), std::string::npos)
      << m;
}

// Bad input: one line naming the file and the place.
TEST(IoRosbag, BadBagsGiveOneLineErrors) {
  CELC_REQUIRE_IO_FIXTURES();
  auto oneLine = [](const std::string& m) { EXPECT_EQ(m.find('\n'), std::string::npos) << m; };
  std::string m = ioErrorOf([] { openEventSource(fixture("bad_truncated.bag")); });
  oneLine(m);
  EXPECT_NE(m.find("bad_truncated.bag: byte 13: index position"), std::string::npos) << m;
  EXPECT_NE(m.find("truncated bag"), std::string::npos) << m;
  EXPECT_NE(m.find("rosbag reindex"), std::string::npos) << m;

  m = ioErrorOf([] { openEventSource(fixture("bad_unindexed.bag")); });
  oneLine(m);
  EXPECT_NE(m.find("bad_unindexed.bag: byte 13: index position 0: the bag has no index"), std::string::npos) << m;
  EXPECT_NE(m.find("rosbag reindex"), std::string::npos) << m;

  m = ioErrorOf([] { openEventSource(fixture("bad_type.bag")); });
  oneLine(m);
  EXPECT_NE(m.find("bad_type.bag: no dvs_msgs/EventArray topic for the events"), std::string::npos) << m;
  EXPECT_NE(m.find("/dvs/events (std_msgs/String)"), std::string::npos) << m;
  ReaderOptions o;
  o.topic_events = "/dvs/events";
  m = ioErrorOf([&] { openEventSource(fixture("bad_type.bag"), o); });
  oneLine(m);
  EXPECT_NE(m.find("topic /dvs/events: unknown message type std_msgs/String"), std::string::npos) << m;
}

// The index decides which topic a message is read as: an index data record
// whose connection is not its messages' (EventArray messages that would decode
// as IMU samples of 1e302 rad/s), or is declared nowhere (messages that would
// vanish), and a chunk info count beyond its data are errors with the byte.
TEST(IoRosbag, IndexConnectionsAndCountsAreCheckedAgainstTheData) {
  CELC_REQUIRE_IO_FIXTURES();
  for (const char* name : {"bad_conn_swapped.bag", "bad_conn_unknown.bag", "bad_chunk_info_count.bag"}) {
    SCOPED_TRACE(name);
    const std::string m = ioErrorOf([&] { openEventSource(fixture(name)); });
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find(std::string(name) + ": byte "), std::string::npos) << m;
    EXPECT_NE(m.find("rosbag reindex"), std::string::npos) << m;
  }
  EXPECT_NE(ioErrorOf([] { openEventSource(fixture("bad_conn_swapped.bag")); })
                .find("points at a message record of connection"),
            std::string::npos);
  EXPECT_NE(ioErrorOf([] { openEventSource(fixture("bad_conn_unknown.bag")); })
                .find("index data record of connection 99, which no connection record of the index declares"),
            std::string::npos);
  EXPECT_NE(ioErrorOf([] { openEventSource(fixture("bad_chunk_info_count.bag")); })
                .find("chunk info record of 2147483647 connection counts"),
            std::string::npos);
}

// Damaged bytes anywhere (compressed and uncompressed chunks, record headers,
// the index): an IoError or a clean read, never a crash, a hang or a huge allocation.
TEST(IoRosbag, DamagedBytesNeverCrash) {
  CELC_REQUIRE_IO_FIXTURES();
  celc::test::TempDir dir;
  std::mt19937 rng(17);
  int errors = 0;
  for (const char* name : {"seq_lz4.bag", "seq_none.bag"}) {
    std::ifstream in(fixture(name), std::ios::binary);
    const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::size_t> records;  // where record headers are ("op=" fields)
    for (std::size_t p = good.find("op="); p != std::string::npos; p = good.find("op=", p + 1)) records.push_back(p);
    std::uniform_int_distribution<std::size_t> at(0, good.size() - 1);
    for (int trial = 0; trial < 40; ++trial) {
      std::string bad = good;
      for (int k = 0; k < 3; ++k) {
        std::size_t p = at(rng);
        if (trial < 10) p = 13 + p % 4096;                                     // the bag header
        else if (trial < 20) p = good.size() - 1 - p % 8192;                   // the index section
        else if (trial < 30) p = records[p % records.size()] - 4 - p % 24;     // record lengths
        bad[p] = char(rng());
      }
      const std::string path = dir.file("bad.bag");
      std::ofstream(path, std::ios::binary) << bad;
      try {
        auto r = openEventSource(path);
        readAllEvents(*r);
        r->readImu();
        r->readPoses();
      } catch (const IoError& e) {
        ++errors;
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
      }
    }
  }
  EXPECT_GT(errors, 10);
}

// Format 1.2 (no chunks; the index points at file positions, the first entry of
// a topic at its message definition record): written here byte by byte.
TEST(IoRosbag, Format12ReadsItsEventsThroughItsIndex) {
  celc::test::TempDir dir;
  const auto ev = celc::test::randomEvents(300, 240, 180, 5);
  const celc::test::Bag12 b = celc::test::bag12(ev, 120, 240, 180);
  std::ofstream(dir.file("old.bag"), std::ios::binary) << b.bytes;

  auto r = openEventSource(dir.file("old.bag"));
  EXPECT_TRUE(hasNote(*r, "bag format 1.2"));
  EXPECT_TRUE(hasNote(*r, "topic /dvs/events: dvs_msgs/EventArray, 2 messages"));
  EXPECT_EQ(r->width(), 240);
  celc::test::expectSameEvents(readAllEvents(*r), ev);

  // an entry off a record's start is an error naming the entry's byte
  std::string bad = b.bytes;
  const std::size_t second_pos = bad.size() - 8;  // the second entry's position field
  const std::uint64_t m2 = b.second_message;
  bad.replace(second_pos, 8, celc::test::BagBytes::le(m2 + 1));
  std::ofstream(dir.file("bad.bag"), std::ios::binary) << bad;
  const std::string m = ioErrorOf([&] { openEventSource(dir.file("bad.bag")); });
  EXPECT_NE(m.find("bad.bag: byte " + std::to_string(second_pos) + ": index entry position " + std::to_string(m2 + 1) +
                   " is not a record's start"),
            std::string::npos)
      << m;
}

// A connection whose MD5 sum is not the decoded layout's is refused by name.
TEST(IoRosbag, AnotherDefinitionUnderAKnownTypeIsAnError) {
  CELC_REQUIRE_IO_FIXTURES();
  celc::test::TempDir dir;
  std::ifstream in(fixture("seq_lz4.bag"), std::ios::binary);
  std::string bag((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string sum = "md5sum=6a62c6daae103f4ff57a132d6f95cec2";  // sensor_msgs/Imu
  const std::size_t at = bag.rfind(sum);                             // the index section's connection record
  ASSERT_NE(at, std::string::npos);
  bag.replace(at + 7, 4, "0000");
  std::ofstream(dir.file("imu.bag"), std::ios::binary) << bag;
  const std::string m = ioErrorOf([&] { openEventSource(dir.file("imu.bag")); });
  EXPECT_NE(m.find("imu.bag: topic /dvs/imu: sensor_msgs/Imu with md5sum 0000c6daae103f4ff57a132d6f95cec2, expected "
                   "6a62c6daae103f4ff57a132d6f95cec2 (the definition celc decodes: Header header, "),
            std::string::npos)
      << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

// Found by fuzz_rosbag: a sensor beyond the bound on a topic whose name holds
// raw bytes is a printable one-line error.
TEST(IoRosbag, HugeSensorOnARawTopicNameIsAPrintableError) {
  celc::test::TempDir dir;
  const auto ev = celc::test::randomEvents(40, 240, 180, 6);
  std::ofstream(dir.file("raw.bag"), std::ios::binary)
      << celc::test::bag12(ev, 20, 83886320, 180, std::string("/dv\xd0\x9a\x01" "ents")).bytes;
  const std::string m = ioErrorOf([&] { openEventSource(dir.file("raw.bag")); });
  EXPECT_NE(m.find("a 83886320x180 sensor (at most 4096)"), std::string::npos) << m;
  for (const char c : m) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << m;
}
