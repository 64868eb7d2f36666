// libFuzzer target: ROS bags. An input that does not start with a bag magic
// line gets "#ROSBAG V2.0\n" in front (format 1.2 stays reachable through its
// own magic, in the dictionary). Reads every event, IMU sample and pose, then,
// when that succeeds, the camera of its CameraInfo as `--calib BAG` does: every
// error must be the reader's one-line IoError.
#include "celc/geometry/undistort.hpp"
#include "celc/io/calibration.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
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
