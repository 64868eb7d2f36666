// What a run reads from a container file (sequence_runner.hpp).
#include "celc/io/event_reader.hpp"
#include "celc/pipeline/sequence_runner.hpp"

namespace celc {

void defaultContainerInputs(RunInputs& inputs, const ReaderOptions& reader) {
  if (!isContainerFile(inputs.events)) return;
  if (inputs.calib.empty() && detectFormat(inputs.events) == Format::RosBag) inputs.calib = inputs.events;
  if (inputs.groundtruth.empty() && !openEventSource(inputs.events, reader)->readPoses().empty())
    inputs.groundtruth = inputs.events;
}

}  // namespace celc
