// libFuzzer target: the YAML files of runs, batches and scenes (one target; the
// first byte picks the reader, so each keeps its own corpus entries).
#include "celc/pipeline/batch.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/render_sequence.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace celc;
  if (size < 1) return 0;
  const int kind = data[0] % 3;
  const std::string path = fuzz::writeInput(kind == 0 ? "run.yaml" : kind == 1 ? "batch.yaml" : "scene.yaml",
                                            data + 1, size - 1);
  fuzz::expectCleanErrors(path, [&] {
    if (kind == 0) {
      (void)loadRunConfig(path);
    } else if (kind == 1) {
      (void)readBatch(path, [](const std::string&) { return RunConfig{}; });
    } else {
      (void)loadSynthConfig(path);
    }
  });
  return 0;
}
