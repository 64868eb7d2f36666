// libFuzzer target for one AEDAT version (CELC_FUZZ_AEDAT = 2, 31 or 4): the
// bytes after the magic line, so that every input reaches that reader. Reads
// every event and IMU sample; AEDAT 4.0 also seeks through its data table.
#include "fuzz_common.hpp"

#ifndef CELC_FUZZ_AEDAT
#error "define CELC_FUZZ_AEDAT (2, 31 or 4)"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
#if CELC_FUZZ_AEDAT == 2
  const std::string magic = "#!AER-DAT2.0\r\n";
#elif CELC_FUZZ_AEDAT == 31
  const std::string magic = "#!AER-DAT3.1\r\n";
#else
  const std::string magic = "#!AER-DAT4.0\r\n";
#endif
  const std::string path = fuzz::writeWithMagic("input.aedat", magic, data, size);
#if CELC_FUZZ_AEDAT == 4
  fuzz::readEverything(path, 1.0e3);
#else
  fuzz::readEverything(path);
#endif
  return 0;
}
