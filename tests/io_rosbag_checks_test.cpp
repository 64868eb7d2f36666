// ROS bags written here (tests/fixtures/bag_writer.hpp) and then damaged byte
// by byte, and message payloads the decoders refuse: what the bag reader
// checks before the bag library reads (the inputs the fuzzer found among
// them). No shared fixture: they also run under the sanitizers
// (scripts/test_sanitize.sh --subset).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "bag_writer.hpp"
#include "celc/io/event_reader.hpp"
#include "io/ros_messages.hpp"
#include "io_test_util.hpp"

using namespace celc;
using celc::test::expectPrintable;
using celc::test::patchBytes;
using celc::test::Place;
using celc::test::readBytes;
using celc::test::TempDir;
using celc::test::writeBytes;

// ---- found by fuzz_rosbag: a connection header whose field length runs past its data ---

TEST(IoRobustness, BagConnectionHeaderFieldBeyondItsDataIsAnError) {
  // A bag with one std_msgs/String message (the test tree's bag writer); then, in the index
  // section, the length of the connection header's `topic=/t` field 8 ->
  // 0x7FFFFFF0: the bag library copied that many bytes out of its buffer while
  // opening the bag (a heap overflow inside librosbag-storage).
  TempDir d;
  const std::string bag = d.file("c.bag");
  {
    namespace rb = celc::test::bag;
    rb::Writer b(bag, rb::Compression::None);
    b.write("/t", rb::messageType("std_msgs/String"), rb::string("hello"), rb::Time{1, 0});
  }
  EXPECT_IO_ERROR(celc::test::drain(bag), "no dvs_msgs/EventArray topic");  // the file as written opens
  // the index section's copy of the field (the chunk holds the other)
  ASSERT_TRUE(patchBytes(bag, std::string("\x08\x00\x00\x00topic=/t", 12), 0, "\xF0\xFF\xFF\x7F", Place::LastOfSeveral));
  EXPECT_IO_ERROR(celc::test::drain(bag), "c.bag: byte ",
                  "connection record data: field of 2147483632 bytes beyond its end");
}

TEST(IoRobustness, Bag12RecordHeaderLongerThanTheFileIsAnError) {
  // Found by the rosbag campaign: a format 1.2 bag (no index checks then) whose
  // first record declares a 1.4 GB header; the bag library allocated it.
  TempDir d;
  std::string b = "#ROSBAG V1.2\n";
  b += std::string("\x00\x00\x50\x53", 4) + "op=\x03" + std::string(40, '\0');
  writeBytes(d.file("o.bag"), b);
  EXPECT_IO_ERROR(celc::test::drain(d.file("o.bag")), "o.bag: byte 13: record: record header length 1397751808",
                  "beyond the end of the file");
}

// ---- a bag's index against its messages ------------------------------------------

TEST(IoRobustness, BagIndexConnectionMustBeItsMessagesConnection) {
  // A bag of two std_msgs/String topics in several chunks (the test tree's bag writer),
  // then three copies: the connection id of the first index data record after
  // the second chunk swapped for the other topic's (the library decoded those
  // messages as the other topic's type) or for an id no connection declares
  // (the messages vanished), and a chunk info's count made 0x7FFFFFFF (the
  // library's "wanted 4 bytes").
  TempDir d;
  const std::string bag = d.file("c.bag");
  namespace rb = celc::test::bag;
  {
    rb::Writer b(bag, rb::Compression::None, 300);
    const auto& type = rb::messageType("std_msgs/String");
    for (std::uint32_t i = 0; i < 12; ++i) {
      b.write("/a", type, rb::string(std::string(64, 'x')), rb::Time{1 + i, 0});
      b.write("/b", type, rb::string(std::string(64, 'x')), rb::Time{1 + i, 5});
    }
  }
  const std::string data = readBytes(bag);
  const auto recs = rb::records(data);
  std::vector<std::size_t> chunks;
  for (std::size_t i = 0; i < recs.size(); ++i)
    if (recs[i].op == 5) chunks.push_back(i);
  ASSERT_GE(chunks.size(), 3u);
  const rb::Record& ix = recs[chunks[1] + 1];
  ASSERT_EQ(ix.op, 4);
  const std::uint64_t conn = rb::readU32(data, ix.at("conn"));
  for (const auto& [ext, value] : {std::pair<const char*, std::uint32_t>{".mis", std::uint32_t(1 - conn)}, {".unk", 7u}}) {
    std::string c = data;
    rb::writeU32(c, ix.at("conn"), value);
    writeBytes(bag + ext, c);
  }
  const rb::Record* info = nullptr;
  for (const auto& r : recs)
    if (r.op == 6 && !info) info = &r;
  ASSERT_NE(info, nullptr);
  {
    std::string c = data;
    rb::writeU32(c, info->at("count"), 0x7FFFFFFF);
    writeBytes(bag + ".ci", c);
  }
  {  // the first message data record of the first chunk: after the /a connection record that opens it
    const rb::Record& chunk = recs[chunks[0]];
    const std::size_t first_data = chunk.data_at + 4 + rb::readU32(data, chunk.data_at) + 4;
    std::string c = data;
    rb::writeU32(c, data.find("conn=", first_data) + 5, 7);
    writeBytes(bag + ".msg", c);
  }
  const std::uint64_t index_at = ix.start, info_at = info->start, chunk_at = recs[chunks[0]].start;
  EXPECT_IO_ERROR(celc::test::drain(bag), "no dvs_msgs/EventArray topic");  // the file as written opens
  const std::string other = std::to_string(1 - conn);
  // the first entry of the index data record: its data follows the header
  EXPECT_IO_ERROR(celc::test::drain(bag + ".mis"), "c.bag.mis: byte ",
                  "index data record of connection " + other + " points at a message record of connection " +
                      std::to_string(conn));
  EXPECT_IO_ERROR(celc::test::drain(bag + ".unk"), "c.bag.unk: byte " + std::to_string(index_at),
                  "index data record of connection 7, which no connection record of the index declares");
  EXPECT_IO_ERROR(celc::test::drain(bag + ".ci"), "c.bag.ci: byte " + std::to_string(info_at),
                  "chunk info record of 2147483647 connection counts (8 bytes each) in 16 bytes of data");
  // a message record inside the first chunk naming connection 7
  EXPECT_IO_ERROR(celc::test::drain(bag + ".msg"), "c.bag.msg: byte " + std::to_string(chunk_at) + ": chunk record at offset ",
                  "message data record of connection 7, which no connection record of the index declares");
  for (const char* ext : {".mis", ".unk", ".ci", ".msg"}) {
    try {
      celc::test::drain(bag + ext);
    } catch (const IoError& e) {
      expectPrintable(e.what());
    }
  }
}

TEST(IoRobustness, BagImuValuesBeyondAnyImuAreAnErrorNotARate) {
  // sensor_msgs/Imu: header (seq, stamp, empty frame_id: 16 bytes), orientation
  // and its covariance (104), angular_velocity at byte 120, its covariance,
  // linear_acceleration at byte 216, its covariance: 312 bytes.
  std::vector<unsigned char> m(312, 0);
  auto put = [&](std::size_t at, double v) { std::memcpy(&m[at], &v, 8); };
  put(120, 0.5);
  put(216 + 16, 9.81);
  const ImuSample s = detail::decodeImu(m.data(), m.size());
  EXPECT_EQ(s.gyro.x(), 0.5);
  EXPECT_EQ(s.accel.z(), 9.81);
  auto offsetOf = [&]() -> std::size_t {
    try {
      detail::decodeImu(m.data(), m.size());
    } catch (const detail::RosDecodeError& e) {
      EXPECT_NE(std::string(e.what()).find("not an IMU sample"), std::string::npos) << e.what();
      return e.offset;
    }
    ADD_FAILURE() << "no error";
    return 0;
  };
  put(120, -1.4e302);  // what an EventArray read as an Imu gave
  EXPECT_EQ(offsetOf(), 120u);
  put(120, 1001.0);  // beyond kMaxImuGyro
  EXPECT_EQ(offsetOf(), 120u);
  put(120, 999.0);
  EXPECT_NO_THROW(detail::decodeImu(m.data(), m.size()));
  put(216, std::nan(""));
  EXPECT_EQ(offsetOf(), 216u);
  put(216, 2e4);  // beyond kMaxImuAccel
  EXPECT_EQ(offsetOf(), 216u);
}
