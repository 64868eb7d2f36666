// libFuzzer target: an events text file (`t x y p`, headers, comments), read
// through format detection, then cut into windows by duration: a far outlier
// timestamp must never make the window source produce windows without bound.
#include "celc/io/window_source.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
  const std::string path = fuzz::writeInput("events.txt", data, size);
  fuzz::expectCleanErrors(path, [&] {
    auto reader = openEventSource(path);
    WindowOptions w;
    w.seconds_per_window = 0.05;
    w.read_batch = 512;
    WindowSource source(*reader, w);
    EventWindow window;
    std::size_t n = 0;
    while (source.next(window))
      if (++n > 100000) fuzz::finding("window source", "more than 100000 windows from a small file");
  });
  fuzz::expectCleanErrors(path, [&] {  // the other options: a sensor size, sorting
    ReaderOptions o;
    o.width = 240;
    o.height = 180;
    o.backwards = BackwardsPolicy::Sort;
    auto reader = openEventSource(path, o);
    (void)readAllEvents(*reader);
  });
  return 0;
}
