#pragma once
/// \file sequence_layout.hpp
/// The RPG / UZH-FPV sequence directory (the Event Camera Dataset layout) and
/// the extra files of `celc synth`: the one place that knows the file names.
/// The reader, the run pipeline, the simulator's writer and the command line
/// all take them from here.
///
///   events.txt       t x y p
///   imu.txt          t ax ay az gx gy gz (or gyro first, UZH-FPV)
///   groundtruth.txt  t px py pz qx qy qz qw
///   calib.yaml       docs/formats.md (preferred), or calib.yml, or
///   calib.txt        fx fy cx cy k1 k2 p1 p2 k3
/// written by `celc synth` besides: labels.txt, twist.txt, twist.yaml, edges.txt.
#include <string>
#include <vector>

namespace celc {

/// File names inside a sequence directory.
namespace sequence_file {
inline constexpr const char* kEvents = "events.txt";
inline constexpr const char* kImu = "imu.txt";
inline constexpr const char* kGroundTruth = "groundtruth.txt";
inline constexpr const char* kCalibYaml = "calib.yaml";
inline constexpr const char* kCalibYml = "calib.yml";
inline constexpr const char* kCalibText = "calib.txt";
// The simulator's extra files (sim/render_sequence.hpp describes them).
inline constexpr const char* kLabels = "labels.txt";
inline constexpr const char* kTwist = "twist.txt";
inline constexpr const char* kTwistYaml = "twist.yaml";
inline constexpr const char* kEdges = "edges.txt";
}  // namespace sequence_file

/// The files found in a sequence directory; a path is empty when its file is absent.
struct SequenceLayout {
  std::string events;
  std::string imu;
  std::string groundtruth;
  std::string calib;  ///< the first of calib.yaml, calib.yml, calib.txt present
};

/// `dir` joined with a file name of the layout.
std::string sequenceFilePath(const std::string& dir, const char* name);
/// True when `path` is a directory holding events.txt.
bool isSequenceDirectory(const std::string& path);
/// Looks the layout's files up in `dir` (regular files only).
SequenceLayout resolveSequenceLayout(const std::string& dir);
/// Calibration file names in order of preference.
const std::vector<const char*>& calibrationFileNames();
/// Every file `celc synth` writes, events.txt first (the order in which a
/// previous run's files are removed: without events.txt a directory is no sequence).
const std::vector<const char*>& simulatedSequenceFiles();
/// "events.txt, imu.txt, groundtruth.txt, calib.yaml|calib.txt": the layout in help texts.
std::string sequenceLayoutSummary();

}  // namespace celc
