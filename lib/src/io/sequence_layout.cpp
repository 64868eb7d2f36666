#include "celc/io/sequence_layout.hpp"

#include <filesystem>
#include <system_error>

namespace fs = std::filesystem;

namespace celc {

namespace {
bool isRegularFile(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}
std::string ifPresent(const std::string& path) { return isRegularFile(path) ? path : std::string(); }
}  // namespace

std::string sequenceFilePath(const std::string& dir, const char* name) { return (fs::path(dir) / name).string(); }

bool isSequenceDirectory(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec) && isRegularFile(sequenceFilePath(path, sequence_file::kEvents));
}

const std::vector<const char*>& calibrationFileNames() {
  static const std::vector<const char*> names{sequence_file::kCalibYaml, sequence_file::kCalibYml,
                                              sequence_file::kCalibText};
  return names;
}

SequenceLayout resolveSequenceLayout(const std::string& dir) {
  SequenceLayout l;
  l.events = ifPresent(sequenceFilePath(dir, sequence_file::kEvents));
  l.imu = ifPresent(sequenceFilePath(dir, sequence_file::kImu));
  l.groundtruth = ifPresent(sequenceFilePath(dir, sequence_file::kGroundTruth));
  for (const char* name : calibrationFileNames()) {
    l.calib = ifPresent(sequenceFilePath(dir, name));
    if (!l.calib.empty()) break;
  }
  return l;
}

const std::vector<const char*>& simulatedSequenceFiles() {
  using namespace sequence_file;
  static const std::vector<const char*> names{kEvents,     kLabels,     kImu,   kGroundTruth, kTwist,
                                              kCalibText, kCalibYaml, kEdges, kTwistYaml};
  return names;
}

std::string sequenceLayoutSummary() {
  using namespace sequence_file;
  return std::string(kEvents) + ", " + kImu + ", " + kGroundTruth + ", " + kCalibYaml + "|" + kCalibText;
}

}  // namespace celc
