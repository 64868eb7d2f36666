// ROS 1 bags (formats 2.0 with uncompressed, bz2 and lz4 chunks, and 1.2)
// read by celc's own bag reader (io/bag_file.hpp: the index at open, each
// chunk decompressed and checked once per pass over a topic), with the few
// message layouts decoded directly (io/ros_messages.hpp). A topic is decoded
// only when its connections carry the type and MD5 sum of the layout the
// decoder reads (kRosTypeSums).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include "io/aedat_readers.hpp"
#include "io/bag_file.hpp"
#include "io/ros_messages.hpp"

namespace celc::detail {
namespace {

/// A topic of the bag: type, connections, count, record-time span.
struct TopicInfo {
  std::string topic, type;
  std::vector<std::uint32_t> conns;
  std::uint64_t messages = 0;
  double t_first = 0.0, t_last = 0.0;
};

/// Seconds of a record time in ns, as ROS's Time::toSec gives them.
double recordSeconds(std::uint64_t ns) {
  return double(ns / 1000000000u) + 1e-9 * double(ns % 1000000000u);
}

class RosBagReader final : public EventReader {
 public:
  RosBagReader(const std::string& path, const ReaderOptions& o) : bag_(path, o.max_packet_bytes) {
    path_ = path;
    options_ = o;
    if (bag_.version() == 200) {
      std::string chunks;
      for (const auto& [name, n] : bag_.compressions())
        chunks += (chunks.empty() ? "" : ", ") + std::to_string(n) + " " + name;
      notes_.push_back("bag format 2.0, chunks: " + (chunks.empty() ? std::string("none") : chunks));
    } else {
      notes_.push_back("bag format 1.2 (no chunks)");
    }
    catalogue();
    events_topic_ = pickTopic(o.topic_events, {ros_type::kEventArray}, "events", "topic_events", true);
    imu_topic_ = pickTopic(o.topic_imu, {ros_type::kImu}, "IMU", "topic_imu", false);
    pose_topic_ = pickTopic(o.topic_pose, {ros_type::kPoseStamped, ros_type::kOdometry}, "pose", "topic_pose", false);
    for (const TopicInfo& t : topics_) {
      char line[512];
      const double span = t.t_last - t.t_first;
      std::snprintf(line, sizeof line, "topic %s: %s, %llu messages, %.4g Hz%s", printable(t.topic, 100).c_str(),
                    printable(t.type, 80).c_str(), static_cast<unsigned long long>(t.messages),
                    t.messages > 1 && span > 0 ? double(t.messages - 1) / span : 0.0,
                    t.topic == events_topic_ ? " (events)" : t.topic == imu_topic_ ? " (IMU)"
                    : t.topic == pose_topic_ ? " (ground truth)" : "");
      notes_.push_back(line);
    }
    readCameraInfo();
    events_ = bag_.messages(topic(events_topic_).conns);
    // The sensor size: the first EventArray's (CameraInfo's when it says 0), unless the options give one.
    if (!events_.empty()) {
      if (side_buf_.chunk >= 0 && side_buf_.chunk == std::int64_t(events_.front().chunk))
        std::swap(side_buf_, events_buf_);  // the camera info's chunk holds the first events too
      msg_ = bag_.message(events_.front(), events_buf_);
      const EventArrayView v = decodeEvents();
      if (v.width > 0 && v.height > 0) {
        width_ = int(std::min<std::uint32_t>(v.width, 1u << 30));
        height_ = int(std::min<std::uint32_t>(v.height, 1u << 30));
      }
      first_loaded_ = true;
    }
    if (width_ > kMaxReaderSensorSide || height_ > kMaxReaderSensorSide)
      throw IoError(path_ + ": topic " + printable(events_topic_, 100) + ": a " + std::to_string(width_) + "x" +
                    std::to_string(height_) + " sensor (at most " + std::to_string(kMaxReaderSensorSide) + ")");
    if (o.width > 0) width_ = o.width;
    if (o.height > 0) height_ = o.height;
  }
  Format format() const override { return Format::RosBag; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    while (batch.size() < max) {
      if (cur_ == count_) {
        if (!nextMessage()) break;
        continue;
      }
      drain(batch, max);
    }
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    std::vector<ImuSample> imu;
    if (imu_topic_.empty()) return imu;
    forEach(imu_topic_, [&](const unsigned char* p, std::size_t n) { imu.push_back(decodeImu(p, n)); });
    return imu;
  }

  std::vector<PoseSample> readPoses() override {
    std::vector<PoseSample> poses;
    if (pose_topic_.empty()) return poses;
    const bool odometry = topic(pose_topic_).type == ros_type::kOdometry;
    forEach(pose_topic_, [&](const unsigned char* p, std::size_t n) {
      poses.push_back(odometry ? decodeOdometry(p, n) : decodePoseStamped(p, n));
    });
    return poses;
  }

  /// The camera of the first sensor_msgs/CameraInfo message (false when the bag has none).
  bool cameraInfo(RosCameraInfo& out) const {
    if (!has_info_) return false;
    out = info_;
    return true;
  }

 private:
  /// topics_ from the connections that have messages (time 0 left out), by name;
  /// a topic of two types is an error.
  void catalogue() {
    std::map<std::uint32_t, TopicInfo> by_conn;  // count and span per connection
    for (const BagEntry& e : bag_.index()) {
      if (e.time_ns == 0) continue;
      TopicInfo& t = by_conn[e.conn];
      const double s = recordSeconds(e.time_ns);
      t.t_first = t.messages == 0 ? s : std::min(t.t_first, s);
      t.t_last = t.messages == 0 ? s : std::max(t.t_last, s);
      ++t.messages;
    }
    std::map<std::string, TopicInfo> by_topic;
    for (const BagConnection& c : bag_.connections()) {
      auto m = by_conn.find(c.id);
      if (m == by_conn.end()) continue;
      TopicInfo& t = by_topic[c.topic];
      if (!t.conns.empty() && t.type != c.type)
        throw IoError(path_ + ": topic " + printable(c.topic, 100) + " carries two message types, " +
                      printable(t.type, 80) + " and " + printable(c.type, 80));
      t.t_first = t.conns.empty() ? m->second.t_first : std::min(t.t_first, m->second.t_first);
      t.t_last = t.conns.empty() ? m->second.t_last : std::max(t.t_last, m->second.t_last);
      t.topic = c.topic;
      t.type = c.type;
      t.conns.push_back(c.id);
      t.messages += m->second.messages;
    }
    for (auto& [name, t] : by_topic) topics_.push_back(t);
  }

  const TopicInfo& topic(const std::string& name) const {
    static const TopicInfo none;
    for (const TopicInfo& t : topics_)
      if (t.topic == name) return t;
    return none;
  }

  std::string topicList() const {
    std::string s;
    for (const TopicInfo& t : topics_) s += (s.empty() ? "" : ", ") + printable(t.topic, 100) + " (" + printable(t.type, 80) + ")";
    return s.empty() ? std::string("none") : s;
  }

  /// Every connection of topic `t` must carry the MD5 sum of the layout its
  /// type is decoded as.
  void checkSums(const TopicInfo& t) const {
    const RosTypeSum* want = rosTypeSum(t.type);
    if (!want) return;
    for (const BagConnection& c : bag_.connections())
      if (c.topic == t.topic && c.md5sum != want->md5sum)
        throw IoError(path_ + ": topic " + printable(t.topic, 100) + ": " + printable(t.type, 80) + " with md5sum " +
                      printable(c.md5sum, 40) + ", expected " + want->md5sum + " (the definition celc decodes: " +
                      want->fields + ")");
  }

  /// The topic named in the options (its type checked), else the one topic of
  /// one of `types`; none is an error only when `required`. The chosen topic's
  /// MD5 sums are checked.
  std::string pickTopic(const std::string& given, const std::vector<std::string>& types, const char* what,
                        const char* key, bool required) {
    auto allowed = [&](const std::string& type) { return std::find(types.begin(), types.end(), type) != types.end(); };
    std::string expected;
    for (const auto& t : types) expected += (expected.empty() ? "" : " or ") + t;
    if (!given.empty()) {
      const std::string type = topic(given).type;
      if (topic(given).conns.empty())
        throw IoError(path_ + ": no topic " + printable(given, 100) + " (input." + key + "); topics: " + topicList());
      if (!allowed(type))
        throw IoError(path_ + ": topic " + printable(given, 100) + ": unknown message type " + printable(type, 80) +
                      " for the " + what + " topic (expected " + expected + ")");
      checkSums(topic(given));
      return given;
    }
    std::vector<std::string> found;
    for (const TopicInfo& t : topics_)
      if (allowed(t.type)) found.push_back(t.topic);
    if (found.size() > 1) {
      std::string names;
      for (const auto& n : found) names += (names.empty() ? "" : ", ") + printable(n, 100);
      throw IoError(path_ + ": several " + what + " topics (" + names + "): choose one with input." + key +
                    " (--" + std::string(key).replace(5, 1, "-") + ")");
    }
    if (found.empty() && required)
      throw IoError(path_ + ": no " + expected + " topic for the " + what + "; topics: " + topicList() +
                    " (input." + key + " names the topic)");
    if (found.empty()) return std::string();
    checkSums(topic(found.front()));
    return found.front();
  }

  /// info_ from the first message of the first CameraInfo topic (by name).
  void readCameraInfo() {
    for (const TopicInfo& t : topics_) {
      if (t.type != ros_type::kCameraInfo) continue;
      checkSums(t);
      const std::vector<BagEntry> entries = bag_.messages(t.conns);
      if (entries.empty()) continue;
      const BagMessage m = bag_.message(entries.front(), side_buf_);
      try {
        info_ = decodeCameraInfo(m.data, m.size);
      } catch (const RosDecodeError& e) {
        throw IoError(path_ + ": topic " + printable(t.topic, 100) + ", message 0, byte " +
                      std::to_string(e.offset) + " of the message: " + e.what());
      }
      has_info_ = true;
      char line[200];
      std::snprintf(line, sizeof line, "camera info on %s: %ux%u, fx %.6g fy %.6g cx %.6g cy %.6g, %s",
                    printable(t.topic, 60).c_str(), info_.width, info_.height, info_.K[0], info_.K[4],
                    info_.K[2], info_.K[5], printable(info_.distortion_model, 30).c_str());
      notes_.push_back(line);
      if (info_.width > 0 && info_.height > 0 && info_.width <= std::uint32_t(kMaxReaderSensorSide) &&
          info_.height <= std::uint32_t(kMaxReaderSensorSide)) {
        width_ = int(info_.width);
        height_ = int(info_.height);
      }
      return;
    }
  }

  EventArrayView decodeEvents() {
    try {
      return decodeEventArray(msg_.data, msg_.size);
    } catch (const RosDecodeError& e) {
      throw IoError(path_ + ": topic " + printable(events_topic_, 100) + ", message " + std::to_string(msg_index_) +
                    ", byte " + std::to_string(e.offset) + " of the message: " + e.what());
    }
  }

  /// The next events message (the first one was loaded by the constructor);
  /// false at the end.
  bool nextMessage() {
    if (first_loaded_) {
      first_loaded_ = false;
    } else {
      if (msg_index_ + 1 >= events_.size()) return false;
      ++msg_index_;
      msg_ = bag_.message(events_[msg_index_], events_buf_);
    }
    const EventArrayView v = decodeEvents();
    events_data_ = v.events;
    events_offset_ = v.events_offset;
    count_ = v.count;
    cur_ = 0;
    return true;
  }

  void drain(std::vector<Event>& batch, std::size_t max) {
    for (; cur_ < count_ && batch.size() < max; ++cur_) {
      const RosEvent r = loadRosEvent(events_data_ + kRosEventBytes * cur_);
      auto where = [&] {
        return path_ + ": topic " + printable(events_topic_, 100) + ", message " + std::to_string(msg_index_) +
               ", event " + std::to_string(cur_);
      };
      if ((width_ > 0 && r.x >= width_) || (height_ > 0 && r.y >= height_)) {
        outsideSensor(where(), double(r.x), double(r.y));
        continue;
      }
      Event e;
      try {
        e.t = rosTimeSeconds(r.sec, r.nsec, events_offset_ + kRosEventBytes * cur_ + 4);
      } catch (const RosDecodeError& err) {
        throw IoError(where() + ": " + err.what());
      }
      e.x = float(r.x);
      e.y = float(r.y);
      e.on = r.on;
      admit(batch, e, where);
    }
  }

  /// decode(data, size) for every message of `name` in time order.
  template <class Decode>
  void forEach(const std::string& name, Decode&& decode) {
    std::uint64_t index = 0;
    for (const BagEntry& e : bag_.messages(topic(name).conns)) {
      const BagMessage m = bag_.message(e, side_buf_);
      try {
        decode(m.data, m.size);
      } catch (const RosDecodeError& err) {
        throw IoError(path_ + ": topic " + printable(name, 100) + ", message " + std::to_string(index) + ", byte " +
                      std::to_string(err.offset) + " of the message: " + err.what());
      }
      ++index;
    }
  }

  BagFile bag_;
  std::vector<TopicInfo> topics_;
  std::string events_topic_, imu_topic_, pose_topic_;
  RosCameraInfo info_;
  bool has_info_ = false;
  std::vector<BagEntry> events_;  ///< the events topic's messages in time order
  bool first_loaded_ = false;
  std::uint64_t msg_index_ = 0;
  ChunkBuffer events_buf_;  ///< the chunk of the current events message
  ChunkBuffer side_buf_;    ///< a chunk read for another topic
  BagMessage msg_;          ///< the current events message
  const unsigned char* events_data_ = nullptr;
  std::size_t events_offset_ = 0;
  std::uint32_t count_ = 0, cur_ = 0;
};

}  // namespace

std::unique_ptr<EventReader> openRosBag(const std::string& path, const ReaderOptions& o) {
  return std::make_unique<RosBagReader>(path, o);
}

bool bagCameraModel(const std::string& path, CameraModel& camera) {
  RosCameraInfo info;
  if (!RosBagReader(path, ReaderOptions{}).cameraInfo(info)) return false;
  auto fail = [&](const std::string& what) { throw IoError(path + ": sensor_msgs/CameraInfo: " + what); };
  if (info.width == 0 || info.height == 0 || info.width > std::uint32_t(kMaxReaderSensorSide) ||
      info.height > std::uint32_t(kMaxReaderSensorSide))
    fail("image size " + std::to_string(info.width) + "x" + std::to_string(info.height) + " out of range");
  camera = CameraModel{};
  camera.width = int(info.width);
  camera.height = int(info.height);
  camera.fx = info.K[0];
  camera.fy = info.K[4];
  camera.cx = info.K[2];
  camera.cy = info.K[5];
  const std::string& model = info.distortion_model;
  bool any = false;
  for (double d : info.D) any |= d != 0.0;
  if (!any) {
    camera.distortion = DistortionModel::None;
  } else if (model == "plumb_bob" || model == "radtan" || (model == "rational_polynomial" && info.D.size() >= 5)) {
    if (model == "rational_polynomial")
      for (std::size_t i = 5; i < info.D.size(); ++i)
        if (info.D[i] != 0.0) fail("rational_polynomial with k4..k6 is not supported (radtan k1 k2 p1 p2 k3 only)");
    camera.distortion = DistortionModel::RadTan;
    for (std::size_t i = 0; i < 5 && i < info.D.size(); ++i) camera.coeffs[i] = info.D[i];
  } else if (model == "equidistant" || model == "fisheye") {
    camera.distortion = DistortionModel::Equidistant;
    for (std::size_t i = 0; i < 4 && i < info.D.size(); ++i) camera.coeffs[i] = info.D[i];
  } else {
    fail("distortion model '" + printable(model, 30) + "' is not supported (plumb_bob, equidistant)");
  }
  if (const std::string err = camera.validate(); !err.empty()) fail(err);
  return true;
}

}  // namespace celc::detail
