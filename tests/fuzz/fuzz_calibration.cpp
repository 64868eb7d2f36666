// libFuzzer target: calibration files, RPG calib.txt and the YAML schema of
// docs/formats.md, from the same bytes. A loaded camera must be within the
// bound the undistortion table accepts.
#include "celc/geometry/undistort.hpp"
#include "celc/io/calibration.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
  auto check = [](const Calibration& c) {
    if (c.camera.width > kMaxSensorSide || c.camera.height > kMaxSensorSide)
      fuzz::finding("calibration", "a sensor beyond the table's bound was accepted");
  };
  const std::string txt = fuzz::writeInput("calib.txt", data, size);
  fuzz::expectCleanErrors(txt, [&] { check(loadCalibration(txt, 240, 180)); });
  const std::string yaml = fuzz::writeInput("calib.yaml", data, size);
  fuzz::expectCleanErrors(yaml, [&] { check(loadCalibration(yaml)); });
  return 0;
}
