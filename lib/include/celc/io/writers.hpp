#pragma once
/// \file writers.hpp
/// Writers for every format the readers take: used by tests (well-formed and
/// deliberately corrupted fixtures), benchmarks and the simulator. Times are
/// rounded to whole microseconds in the binary formats. Throw IoError on I/O failure.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"

namespace celc {

struct TextWriteOptions {
  bool crlf = false;            ///< "\r\n" line endings
  bool id_column = false;       ///< a leading running id column (UZH-FPV)
  std::string header;           ///< written as "# <header>" when non-empty
  bool final_newline = true;    ///< false: omit the last "\n"
};

/// `t x y p` per line (p 0/1), 9 decimals for t.
void writeEventsText(const std::string& path, const std::vector<Event>& events, const TextWriteOptions& o = {});

/// The events text line `t x y p` (p 0/1, no line end): the one place that
/// spells it. t in seconds with 9 decimals, as writeEventsText writes it; the
/// contract of snprintf (at most `cap` chars with the NUL; returns the length).
int formatEventLine(char* out, std::size_t cap, double t, int x, int y, bool on);
/// Room putEventLineMicros needs.
inline constexpr std::size_t kEventLineMicrosMaxChars = 48;
/// The same line with t given in whole microseconds, written as seconds with
/// exactly 6 decimals (no rounding: the simulator's events.txt, written in
/// pieces). Returns the end of the line.
char* putEventLineMicros(char* out, std::int64_t t_us, int x, int y, bool on);
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

}  // namespace celc
