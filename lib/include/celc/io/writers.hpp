#pragma once
/// \file writers.hpp
/// Writers for every format the readers take: used by tests (well-formed and
/// deliberately corrupted fixtures), benchmarks and the simulator. Times are
/// rounded to whole microseconds in the binary formats. Throw IoError on I/O failure.
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc::io {

struct TextWriteOptions {
  bool crlf = false;            ///< "\r\n" line endings
  bool id_column = false;       ///< a leading running id column (UZH-FPV)
  std::string header;           ///< written as "# <header>" when non-empty
  bool final_newline = true;    ///< false: omit the last "\n"
};

/// `t x y p` per line (p 0/1), 9 decimals for t.
void writeEventsText(const std::string& path, const std::vector<Event>& events, const TextWriteOptions& o = {});
/// `t ax ay az gx gy gz` (gyro_first = false) or `t gx gy gz ax ay az`.
void writeImuText(const std::string& path, const std::vector<ImuSample>& imu, bool gyro_first,
                  const TextWriteOptions& o = {});
/// `t px py pz qx qy qz qw`.
void writePosesText(const std::string& path, const std::vector<PoseSample>& poses, const TextWriteOptions& o = {});

/// AEDAT 2.0, DAVIS layout, chip name in the header (sets the sensor size: the
/// events must fit it), IMU quantised with the given full scales (deg/s, g).
void writeAedat2(const std::string& path, const std::vector<Event>& events, const std::vector<ImuSample>& imu,
                 const std::string& chip = "DAVIS240C", int gyro_full_scale_dps = 1000, int accel_full_scale_g = 8);

/// AEDAT 3.1, source 1 named `chip`, polarity packets of `per_packet` events, IMU6 packets.
void writeAedat31(const std::string& path, const std::vector<Event>& events, const std::vector<ImuSample>& imu,
                  const std::string& chip = "DAVIS240C", int per_packet = 4096);

enum class Aedat4Compression { None = 0, Lz4 = 1, Zstd = 3 };
/// AEDAT 4.0 with an events stream (id 0, width x height) and an IMU stream
/// (id 1), packets of `per_packet` events, optionally a file data table.
void writeAedat4(const std::string& path, const std::vector<Event>& events, const std::vector<ImuSample>& imu,
                 int width, int height, Aedat4Compression compression, int per_packet = 4096,
                 bool data_table = true);

}  // namespace celc::io
