#include "celc/io/event_reader.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "celc/io/sequence_layout.hpp"
#include "celc/io/text_io.hpp"
#include "io/aedat_readers.hpp"

namespace celc {

static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE float sizes expected");

std::string toString(Format format) {
  switch (format) {
    case Format::Text: return "events text";
    case Format::RpgDirectory: return "RPG/UZH-FPV directory";
    case Format::Aedat2: return "AEDAT 2.0";
    case Format::Aedat31: return "AEDAT 3.1";
    case Format::Aedat4: return "AEDAT 4.0";
  }
  return "unknown";
}

std::string toString(ImuColumns columns) {
  switch (columns) {
    case ImuColumns::Auto: return "auto";
    case ImuColumns::RpgAccelFirst: return "rpg";
    case ImuColumns::GyroFirst: return "gyro_first";
  }
  return "auto";
}

ImuColumns parseImuColumns(const std::string& name) {
  if (name == "auto") return ImuColumns::Auto;
  if (name == "rpg" || name == "accel_first") return ImuColumns::RpgAccelFirst;
  if (name == "gyro_first" || name == "uzh_fpv") return ImuColumns::GyroFirst;
  throw std::invalid_argument("unknown IMU column order '" + name + "' (auto | rpg | gyro_first)");
}

std::string ReaderOptions::validate() const {
  if (width < 0 || height < 0) return "width and height must be >= 0";
  if ((width == 0) != (height == 0)) return "give both width and height, or neither";
  if (width > 65535 || height > 65535) return "width and height must be <= 65535";
  if (!(text_time_scale > 0.0) || !std::isfinite(text_time_scale)) return "text_time_scale must be > 0";
  if (max_packet_bytes < 1024) return "max_packet_bytes must be >= 1024";
  if (aedat_source < -1 || aedat_source > 32767) return "aedat_source must be -1 or a source id";
  return {};
}

void EventReader::warn(std::uint64_t ReaderWarnings::*counter, const std::string& message) {
  if (options_.strict) throw IoError(message + " (strict mode)");
  ++(warnings_.*counter);
  if (warnings_.messages.size() < 20) warnings_.messages.push_back(message);
}

namespace {
bool isDir(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}
bool exists(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}
}  // namespace

Format detectFormat(const std::string& path) {
  if (isDir(path)) {
    if (!isSequenceDirectory(path))
      throw IoError(path + ": directory without " + sequence_file::kEvents + " (expected the RPG / UZH-FPV layout)");
    return Format::RpgDirectory;
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw IoError(path + ": cannot open: " + std::strerror(errno));
  char buf[16] = {0};
  const std::size_t got = std::fread(buf, 1, sizeof(buf), f);
  std::fclose(f);
  const std::string head(buf, got);
  if (head.rfind("#!AER-DAT2.0", 0) == 0) return Format::Aedat2;
  if (head.rfind("#!AER-DAT3.1", 0) == 0) return Format::Aedat31;
  if (head.rfind("#!AER-DAT4.0", 0) == 0) return Format::Aedat4;
  if (head.rfind("#!AER-DAT", 0) == 0)
    throw IoError(path + ": byte 0: unsupported AEDAT version '" + head.substr(0, 12) + "'");
  // a binary file that is not AEDAT: refuse instead of parsing garbage as text
  for (std::size_t i = 0; i < got; ++i)
    if (buf[i] == 0) throw IoError(path + ": byte " + std::to_string(i) + ": binary data without an AEDAT magic line");
  return Format::Text;
}

std::unique_ptr<EventReader> openEventSource(const std::string& path, const ReaderOptions& options) {
  const std::string err = options.validate();
  if (!err.empty()) throw IoError(path + ": invalid reader options: " + err);
  switch (detectFormat(path)) {
    case Format::RpgDirectory: {
      const SequenceLayout layout = resolveSequenceLayout(path);
      auto reader = openTextEvents(layout.events, layout.imu, options);
      for (const char* f : {sequence_file::kImu, sequence_file::kGroundTruth, sequence_file::kCalibText})
        reader->addNote(std::string(f) + (exists(sequenceFilePath(path, f)) ? " present" : " absent"));
      return reader;
    }
    case Format::Text: return openTextEvents(path, "", options);
    case Format::Aedat2: return detail::openAedat2(path, options);
    case Format::Aedat31: return detail::openAedat31(path, options);
    case Format::Aedat4: return detail::openAedat4(path, options);
  }
  throw IoError(path + ": unknown format");
}

std::vector<Event> readAllEvents(EventReader& reader) {
  std::vector<Event> all, batch;
  while (reader.next(batch, 1 << 16)) all.insert(all.end(), batch.begin(), batch.end());
  return all;
}

FileInfo scanFile(const std::string& path, const ReaderOptions& options) {
  FileInfo info;
  info.path = path;
  info.format = detectFormat(path);
  auto reader = openEventSource(path, options);
  info.width = reader->width();
  info.height = reader->height();
  std::vector<Event> batch;
  bool first = true;
  while (reader->next(batch, 1 << 16)) {
    for (const Event& e : batch) {
      if (first) {
        info.t_first = info.t_min = info.t_max = e.t;
        first = false;
      }
      info.t_min = std::min(info.t_min, e.t);
      info.t_max = std::max(info.t_max, e.t);
      info.max_x = std::max(info.max_x, int(e.x));
      info.max_y = std::max(info.max_y, int(e.y));
      info.on_events += e.on ? 1 : 0;
    }
    info.events += batch.size();
    info.t_last = batch.back().t;
  }
  info.warnings = reader->warnings();
  info.notes = reader->notes();
  const auto imu = reader->readImu();
  info.imu_samples = imu.size();
  if (!imu.empty()) {
    info.imu_t_first = imu.front().t;
    info.imu_t_last = imu.back().t;
  }
  return info;
}

}  // namespace celc
