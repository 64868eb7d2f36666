#pragma once
/// \file text_io.hpp
/// RPG / Event Camera Dataset / UZH-FPV text files, parsed with large buffered
/// reads and std::from_chars (no per-line iostreams).
///  - events:  `t x y p`, or `id t x y p`; p in {0,1} or {-1,1}
///  - IMU:     `t ax ay az gx gy gz` (RPG) or `id t wx wy wz ax ay az` (UZH-FPV);
///             gyro [rad/s], accel [m/s^2]
///  - poses:   `t px py pz qx qy qz qw`, or with a leading id column
/// Separators: spaces, tabs or commas; `#` lines are comments, or a header
/// naming the columns (then the column order comes from it); CRLF endings and a
/// missing final newline are accepted. Timestamps are multiplied by
/// ReaderOptions::text_time_scale.
#include <memory>
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc {

/// Streaming reader of an events text file; `imu_path` (may be empty) is read by readImu().
std::unique_ptr<EventReader> openTextEvents(const std::string& events_path,
                                            const std::string& imu_path,
                                            const ReaderOptions& options = {});

/// All IMU samples of an IMU text file. Throws IoError (file and line).
std::vector<ImuSample> readImuText(const std::string& path, const ReaderOptions& options = {});

/// All poses T_world_body of a ground-truth text file (quaternion normalised;
/// a zero quaternion is an error). Throws IoError (file and line). A ROS bag
/// or HDF5 file given instead gives the poses it carries (EventReader::readPoses).
std::vector<PoseSample> readPosesText(const std::string& path, const ReaderOptions& options = {});

}  // namespace celc
