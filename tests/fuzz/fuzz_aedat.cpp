// libFuzzer target for one AEDAT version (CELC_FUZZ_AEDAT = 2, 31 or 4): the
// bytes after the magic line, so that every input reaches that reader. Reads
// every event and IMU sample; AEDAT 4.0 also seeks through its data table.
#include <cstring>

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
  // seeds are whole files: drop their magic line when present
  if (size >= magic.size() && std::memcmp(data, magic.data(), magic.size()) == 0) {
    data += magic.size();
    size -= magic.size();
  }
  std::string bytes = magic;
  bytes.append(reinterpret_cast<const char*>(data), size);
  const std::string path =
      fuzz::writeInput("input.aedat", reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  fuzz::expectCleanErrors(path, [&] {
    auto reader = openEventSource(path);
    std::vector<Event> batch;
    while (reader->next(batch, 1000)) {
    }
    (void)reader->readImu();
  });
#if CELC_FUZZ_AEDAT == 4
  fuzz::expectCleanErrors(path, [&] {
    auto reader = openEventSource(path);
    if (reader->seekTime(1.0e3)) {
      std::vector<Event> batch;
      (void)reader->next(batch, 1000);
    }
  });
#endif
  return 0;
}
