// libFuzzer target: HDF5 event files (DSEC and MVSEC layouts). An input that
// does not start with the HDF5 signature gets it in front. Reads every event,
// IMU sample and pose, then seeks through /ms_to_idx (DSEC) and reads a batch.
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string kSignature("\x89HDF\r\n\x1a\n", 8);
  const std::string path = celc::fuzz::writeWithMagic("input.h5", kSignature, data, size);
  celc::fuzz::readEverything(path, 1.0005);
  return 0;
}
