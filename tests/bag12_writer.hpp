#pragma once
// A ROS bag of format 1.2 written byte by byte (the ROS writers make 2.0):
// one dvs_msgs/EventArray topic, its message
// definition record, its messages, and the index (one index data record whose
// first entry points at the definition record). Used by the bag tests and the
// fuzz seeds.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/types.hpp"

namespace celc::test {

/// Bytes of ROS 1 bag records: header fields ("name=value", each after its
/// uint32 length), then the data after its length.
struct BagBytes {
  std::string s;
  template <typename T>
  static std::string le(T v) {
    return std::string(reinterpret_cast<const char*>(&v), sizeof v);
  }
  static std::string field(const std::string& name, const std::string& value) {
    return le(std::uint32_t(name.size() + 1 + value.size())) + name + "=" + value;
  }
  /// Appends a record; returns its position.
  std::size_t record(const std::vector<std::string>& fields, const std::string& data) {
    const std::size_t at = s.size();
    std::string h;
    for (const auto& f : fields) h += f;
    s += le(std::uint32_t(h.size())) + h + le(std::uint32_t(data.size())) + data;
    return at;
  }
};

/// A serialised dvs_msgs/EventArray (header stamp = the first event's time;
/// times in whole microseconds).
inline std::string eventArrayBytes(const std::vector<Event>& ev, std::uint32_t width, std::uint32_t height) {
  using B = BagBytes;
  auto sec = [](double t) { return std::uint32_t(std::llround(t * 1e6) / 1000000); };
  auto nsec = [](double t) { return std::uint32_t(std::llround(t * 1e6) % 1000000 * 1000); };
  std::string m = B::le(std::uint32_t(0)) + B::le(sec(ev.at(0).t)) + B::le(nsec(ev.at(0).t)) + B::le(std::uint32_t(0)) +
                  B::le(height) + B::le(width) + B::le(std::uint32_t(ev.size()));
  for (const Event& e : ev)
    m += B::le(std::uint16_t(e.x)) + B::le(std::uint16_t(e.y)) + B::le(sec(e.t)) + B::le(nsec(e.t)) +
         char(e.on ? 1 : 0);
  return m;
}

/// A format 1.2 bag of `ev` in two EventArray messages of topic `topic` (the
/// first holds `split` events), recorded at 10 s and 11 s; the index's second entry, the
/// file's last 8 bytes, holds `second_message`, the second message's position.
struct Bag12 {
  std::string bytes;
  std::uint64_t second_message = 0;
};
inline Bag12 bag12(const std::vector<Event>& ev, std::size_t split, std::uint32_t width, std::uint32_t height,
                   const std::string& topic = "/dvs/events") {
  using B = BagBytes;
  B b;
  b.s = "#ROSBAG V1.2\n";
  const std::size_t head = b.record({B::field("op", "\x03"), B::field("index_pos", B::le(std::uint64_t(0)))},
                                    std::string(64, ' '));
  const std::string md5 = "5e8beee5a6c107e504c2e78903c224b8";
  const std::size_t def = b.record({B::field("op", "\x01"), B::field("topic", topic), B::field("md5", md5),
                                    B::field("type", "dvs_msgs/EventArray"), B::field("def", "Header header\n")},
                                   "");
  auto message = [&](const std::vector<Event>& e) {
    return b.record({B::field("op", "\x02"), B::field("topic", topic), B::field("md5", md5),
                     B::field("type", "dvs_msgs/EventArray")},
                    eventArrayBytes(e, width, height));
  };
  message(std::vector<Event>(ev.begin(), ev.begin() + std::ptrdiff_t(split)));
  Bag12 out;
  out.second_message = message(std::vector<Event>(ev.begin() + std::ptrdiff_t(split), ev.end()));
  const std::size_t index_pos = b.s.size();
  const std::string entries = B::le(std::uint32_t(10)) + B::le(std::uint32_t(0)) + B::le(std::uint64_t(def)) +
                              B::le(std::uint32_t(11)) + B::le(std::uint32_t(0)) + B::le(out.second_message);
  b.record({B::field("op", "\x04"), B::field("ver", B::le(std::uint32_t(0))), B::field("topic", topic),
            B::field("count", B::le(std::uint32_t(2)))},
           entries);
  const std::string index_field = "index_pos=";
  b.s.replace(b.s.find(index_field, head) + index_field.size(), 8, B::le(std::uint64_t(index_pos)));
  out.bytes = std::move(b.s);
  return out;
}

}  // namespace celc::test
