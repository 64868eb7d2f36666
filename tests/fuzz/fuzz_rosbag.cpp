// libFuzzer target: ROS bags. An input that does not start with a bag magic
// line gets "#ROSBAG V2.0\n" in front (format 1.2 stays reachable through its
// own magic, in the dictionary). Reads every event, IMU sample and pose, then,
// when that succeeds, the camera of its CameraInfo as `--calib BAG` does: every
// error must be the reader's one-line IoError, never the bag library's exception.
//
// Speed: every rosbag::Bag loads the bag library's encryptor plugin through
// class_loader and unloads it when it closes (dlopen / dlclose, relocations,
// unmapping: most of the time of an input). One empty bag held open for the
// whole process keeps the plugin loaded, so the readers' own Bags only take a
// reference; what they check is unchanged.
#include <rosbag/bag.h>

#include "celc/geometry/undistort.hpp"
#include "celc/io/calibration.hpp"
#include "fuzz_common.hpp"

namespace {

/// An indexed bag 2.0 without connections or chunks: the magic line and the
/// bag header record {op 0x03, index_pos = its end, conn_count 0, chunk_count 0}.
std::string emptyBag() {
  std::string header;
  auto field = [&](const std::string& name, const void* value, std::uint32_t n) {
    const std::uint32_t len = std::uint32_t(name.size() + 1 + n);
    header.append(reinterpret_cast<const char*>(&len), 4);
    header += name + "=";
    header.append(static_cast<const char*>(value), n);
  };
  const std::uint8_t op = 0x03;
  const std::uint32_t zero = 0, data_len = 0;
  std::string bag = "#ROSBAG V2.0\n";
  // the index position is the end of the file: 13 + 4 + header + 4
  const std::uint64_t index_pos = 13 + 4 + (4 + 3 + 1) + (4 + 10 + 8) + (4 + 11 + 4) + (4 + 12 + 4) + 4;
  field("op", &op, 1);
  field("index_pos", &index_pos, 8);
  field("conn_count", &zero, 4);
  field("chunk_count", &zero, 4);
  const std::uint32_t hlen = std::uint32_t(header.size());
  bag.append(reinterpret_cast<const char*>(&hlen), 4);
  bag += header;
  bag.append(reinterpret_cast<const char*>(&data_len), 4);
  if (bag.size() != index_pos) std::abort();
  return bag;
}

/// The bag that holds the encryptor plugin (never closed); null when it cannot be opened.
void holdEncryptorPlugin() {
  static rosbag::Bag* held = [] {
    const std::string bag = emptyBag();
    const std::string path = celc::fuzz::writeInput("held.bag", reinterpret_cast<const std::uint8_t*>(bag.data()),
                                                    bag.size());
    auto* b = new rosbag::Bag;
    try {
      b->open(path, rosbag::bagmode::Read);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fuzz_rosbag: the empty bag does not open (%s): every input loads the plugin\n", e.what());
    }
    return b;
  }();
  (void)held;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
  holdEncryptorPlugin();
  static const std::string kMagic = "#ROSBAG V";
  const bool has_magic = size >= kMagic.size() && std::memcmp(data, kMagic.data(), kMagic.size()) == 0;
  const std::string path = has_magic ? fuzz::writeInput("input.bag", data, size)
                                     : fuzz::writeWithMagic("input.bag", "#ROSBAG V2.0\n", data, size);
  if (!fuzz::readEverything(path)) return 0;  // the calibration would open the bag the same way
  fuzz::expectCleanErrors(path, [&] {
    const Calibration c = loadCalibration(path);
    if (c.camera.width > kMaxSensorSide || c.camera.height > kMaxSensorSide)
      fuzz::finding("bag calibration", "a sensor beyond the table's bound was accepted");
  });
  return 0;
}
