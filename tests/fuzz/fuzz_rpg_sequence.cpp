// libFuzzer target: the other files of an RPG / UZH-FPV sequence directory,
// imu.txt (every column order) and groundtruth.txt, from the same bytes.
#include "celc/io/text_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
  const std::string imu = fuzz::writeInput("imu.txt", data, size);
  for (ImuColumns c : {ImuColumns::Auto, ImuColumns::GyroFirst}) {
    fuzz::expectCleanErrors(imu, [&] {
      ReaderOptions o;
      o.imu_columns = c;
      (void)readImuText(imu, o);
    });
  }
  const std::string gt = fuzz::writeInput("groundtruth.txt", data, size);
  fuzz::expectCleanErrors(gt, [&] { (void)readPosesText(gt); });
  return 0;
}
