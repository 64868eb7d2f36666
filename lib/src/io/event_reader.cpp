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
    case Format::RosBag: return "ROS bag";
    case Format::Hdf5: return "HDF5";
  }
  return "unknown";
}

bool isContainerFormat(Format format) { return format == Format::RosBag || format == Format::Hdf5; }

std::string toString(ImuColumns columns) {
  switch (columns) {
    case ImuColumns::Auto: return "auto";
    case ImuColumns::RpgAccelFirst: return "rpg";
    case ImuColumns::GyroFirst: return "gyro_first";
  }
  return "auto";
}

std::string toString(BackwardsPolicy policy) {
  switch (policy) {
    case BackwardsPolicy::Error: return "error";
    case BackwardsPolicy::Drop: return "drop";
    case BackwardsPolicy::Sort: return "sort";
  }
  return "error";
}

ImuColumns parseImuColumns(const std::string& name) {
  if (name == "auto") return ImuColumns::Auto;
  if (name == "rpg" || name == "accel_first") return ImuColumns::RpgAccelFirst;
  if (name == "gyro_first" || name == "uzh_fpv") return ImuColumns::GyroFirst;
  throw std::invalid_argument("unknown IMU column order '" + name + "' (auto | rpg | gyro_first)");
}

ReaderOptions::ReaderOptions() = default;

std::string ReaderOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if ((width == 0) != (height == 0)) e += "width, height: give both, or neither; ";
  for (const std::string* topic : {&topic_events, &topic_imu, &topic_pose})
    if (topic->size() > 256 || detail::firstNonTextByte(*topic) != std::string::npos) {
      e += "topic_events, topic_imu, topic_pose: a topic name must be text of at most 256 characters; ";
      break;
    }
  return e;
}

namespace detail {
std::size_t firstNonTextByte(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto u = static_cast<unsigned char>(s[i]);
    if (u < 0x80) {
      if ((u < 0x20 && u != '\t' && u != '\n' && u != '\r' && u != '\f') || u == 0x7F) return i;
      ++i;
      continue;
    }
    // UTF-8 sequence: lead byte then 1..3 continuation bytes (a cut at the end is fine)
    const std::size_t n = (u & 0xE0) == 0xC0 ? 1 : (u & 0xF0) == 0xE0 ? 2 : (u & 0xF8) == 0xF0 ? 3 : 0;
    if (n == 0 || u == 0xC0 || u == 0xC1 || u > 0xF4) return i;
    for (std::size_t k = 1; k <= n; ++k) {
      if (i + k >= s.size()) return std::string::npos;
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return i;
    }
    i += n + 1;
  }
  return std::string::npos;
}

std::string printable(const std::string& s, std::size_t max) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  std::size_t shown = 0;
  for (const char ch : s) {
    if (shown == max) {
      out += "...";
      break;
    }
    const auto u = static_cast<unsigned char>(ch);
    if (u >= 0x20 && u < 0x7F) {
      out.push_back(ch);
    } else {
      out += "\\x";
      out.push_back(hex[u >> 4]);
      out.push_back(hex[u & 15]);
    }
    ++shown;
  }
  return out;
}
}  // namespace detail

void EventReader::warn(std::uint64_t ReaderWarnings::*counter, const std::string& message) {
  const std::string m = detail::printable(message, 400);
  if (options_.strict) throw IoError(m + " (strict mode)");
  ++(warnings_.*counter);
  if (warnings_.messages.size() < 20) warnings_.messages.push_back(m);
}

void EventReader::warnTruncated(std::uint64_t file_end, const std::string& message) {
  warn(&ReaderWarnings::truncated, message);
  warnings_.truncated_at = file_end;
}

void EventReader::outsideSensor(const std::string& where, double x, double y) {
  char px[96];
  std::snprintf(px, sizeof px, "pixel (%g, %g) outside the %dx%d sensor", x, y, width_, height_);
  warn(&ReaderWarnings::outside_sensor, where + ": " + px);
  const std::uint64_t n = warnings_.outside_sensor;
  const std::uint64_t seen = admitted_ + n;
  if (n >= 100 && double(n) > options_.max_outside_share * double(seen)) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  ": %llu of %llu events so far have pixels outside the %dx%d sensor (more than "
                  "input.max_outside_share = %g): wrong sensor size? (input.width / input.height)",
                  static_cast<unsigned long long>(n), static_cast<unsigned long long>(seen), width_, height_,
                  options_.max_outside_share);
    throw IoError(where + msg);
  }
}

std::size_t EventReader::startBatch(std::vector<Event>& batch, std::size_t max) {
  batch.clear();
  if (max == 0) max = 1;
  batch_max_ = max;
  const std::size_t k = std::min(max, ready_.size());
  batch.assign(ready_.begin(), ready_.begin() + std::ptrdiff_t(k));
  ready_.erase(ready_.begin(), ready_.begin() + std::ptrdiff_t(k));
  return max;
}

void EventReader::accept(std::vector<Event>& out, const Event& e) {
  prev_t_ = e.t;
  have_prev_ = true;
  // A held event passed on with the one that releases it may be one more than the batch takes.
  auto emit = [&](const Event& x) {
    if (out.size() < batch_max_) out.push_back(x);
    else ready_.push_back(x);
  };
  if (options_.backwards != BackwardsPolicy::Sort) {
    emit(e);
    return;
  }
  reorder_.push(e);
  if (reorder_.size() > kSortBufferEvents) {
    const Event first = reorder_.top();
    reorder_.pop();
    if (emitted_any_ && first.t < last_emitted_) {
      warn(&ReaderWarnings::backwards_time,
           path_ + ": an event at " + std::to_string(first.t) + " s arrived more than " +
               std::to_string(kSortBufferEvents) + " events late for the sort buffer: dropped");
      ++warnings_.backwards_dropped;
      return;
    }
    emitted_any_ = true;
    last_emitted_ = first.t;
    emit(first);
  }
}

bool EventReader::admitStart(std::vector<Event>& out, const Event& e, const std::string& where) {
  const double J = options_.max_time_jump;
  char msg[320];
  auto dropOutlier = [&](const Event& o, const std::string& at, const char* what) {
    std::snprintf(msg, sizeof msg, ": timestamp %.6g s %s: outlier dropped (input.max_time_jump = %g s)", o.t, what, J);
    warn(&ReaderWarnings::time_jumps, at + msg);
    ++warnings_.time_outliers;
  };
  if (start_ == Start::None) {
    first_ = e;
    first_where_ = where;
    start_ = Start::First;
    return true;
  }
  if (start_ == Start::First) {
    if (first_.t - e.t > J) {  // far before the first: which of the two is wrong, the third event says
      second_ = e;
      second_where_ = where;
      start_ = Start::Second;
      return true;
    }
    start_ = Start::Done;
    accept(out, first_);
    return false;
  }
  // Start::Second: the first event lies more than J after the second.
  start_ = Start::Done;
  if (std::abs(e.t - first_.t) <= J && std::abs(e.t - second_.t) > J) {
    dropOutlier(second_, second_where_, "lies before the first event and the next comes back");
    accept(out, first_);
  } else {
    dropOutlier(first_, first_where_, "of the first event lies ahead of the events that follow");
    accept(out, second_);
  }
  return false;
}

void EventReader::admitSlow(std::vector<Event>& out, const Event& e, const std::string& where) {
  char msg[320];
  if (start_ != Start::Done && admitStart(out, e, where)) return;
  const double J = options_.max_time_jump;
  if (holding_) {
    holding_ = false;
    if (std::abs(e.t - held_.t) <= J) {  // the next event confirms the jump: a gap in the recording
      std::snprintf(msg, sizeof msg, ": timestamp %.6f s follows %.6f s: a gap of %.6g s (more than input.max_time_jump = %g s)",
                    held_.t, prev_t_, held_.t - prev_t_, J);
      warn(&ReaderWarnings::time_jumps, held_where_ + msg);
      accept(out, held_);
    } else {
      std::snprintf(msg, sizeof msg,
                    ": timestamp %.6g s jumps %.6g s ahead of the previous event and the next comes back: "
                    "outlier dropped (input.max_time_jump = %g s)",
                    held_.t, held_.t - prev_t_, J);
      warn(&ReaderWarnings::time_jumps, held_where_ + msg);
      ++warnings_.time_outliers;
    }
  }
  const double d = e.t - prev_t_;
  if (d > J) {  // hold it until the next event says whether it is an outlier or a gap
    holding_ = true;
    held_ = e;
    held_where_ = where;
    return;
  }
  // prev_t_ is the latest time so far (kept and sorted events leave it), so
  // that decreases add up against the tolerance: a stream walking back in
  // small steps goes beyond it as a whole.
  if (d < 0.0) {
    const bool beyond = -d > options_.backwards_tolerance;
    if (!beyond || options_.backwards == BackwardsPolicy::Sort) {
      std::snprintf(msg, sizeof msg, ": timestamp %.6f s is %.6g s before the latest event so far (%s)", e.t, -d,
                    beyond ? "sorted" : "kept");
      warn(&ReaderWarnings::backwards_time, where + msg);
      if (beyond) ++warnings_.backwards_sorted;
      const double keep = prev_t_;
      accept(out, e);
      prev_t_ = keep;
      return;
    }
    if (options_.backwards == BackwardsPolicy::Drop) {
      std::snprintf(msg, sizeof msg, ": timestamp %.6f s is %.6g s before the latest event so far: dropped", e.t, -d);
      warn(&ReaderWarnings::backwards_time, where + msg);
      ++warnings_.backwards_dropped;
      return;
    }
    std::snprintf(msg, sizeof msg,
                  ": timestamp %.6f s is %.6g s before the latest event so far (more than input.backwards_tolerance = "
                  "%g s): the events are not time-ordered (input.backwards: drop or sort)",
                  e.t, -d, options_.backwards_tolerance);
    throw IoError(where + msg);
  }
  accept(out, e);
}

void EventReader::release(std::vector<Event>& out, std::size_t max) {
  if (start_ == Start::First) accept(out, first_);  // a single event
  if (start_ == Start::Second) {  // two events and nothing after them: the later one is taken for the outlier
    char msg[200];
    std::snprintf(msg, sizeof msg,
                  ": timestamp %.6g s of the first event lies ahead of the event that follows: outlier dropped "
                  "(input.max_time_jump = %g s)",
                  first_.t, options_.max_time_jump);
    warn(&ReaderWarnings::time_jumps, first_where_ + msg);
    ++warnings_.time_outliers;
    accept(out, second_);
  }
  start_ = Start::Done;
  if (holding_) {  // a jump at the very end: nothing confirms or refutes it; keep it, reported
    holding_ = false;
    char msg[200];
    std::snprintf(msg, sizeof msg, ": the last event jumps %.6g s ahead (more than input.max_time_jump = %g s)",
                  held_.t - prev_t_, options_.max_time_jump);
    warn(&ReaderWarnings::time_jumps, held_where_ + msg);
    accept(out, held_);
  }
  while (!reorder_.empty() && out.size() < max) {
    out.push_back(reorder_.top());
    emitted_any_ = true;
    last_emitted_ = reorder_.top().t;
    reorder_.pop();
  }
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

/// Format::RosBag / Format::Hdf5 from the first bytes of a file, else Format::Text.
static Format containerMagic(const std::string& head) {
  if (head.rfind("#ROSBAG V", 0) == 0) return Format::RosBag;
  // The HDF5 superblock signature sits at byte 0, 512, 1024 or 2048 (after a user block).
  static const char kHdf5Signature[] = "\x89HDF\r\n\x1a\n";
  for (std::size_t at : {0, 512, 1024, 2048})
    if (head.size() >= at + 8 && head.compare(at, 8, kHdf5Signature, 8) == 0) return Format::Hdf5;
  return Format::Text;
}

bool isContainerFile(const std::string& path) {
  if (!exists(path)) return false;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  std::string head(2056, '\0');
  head.resize(std::fread(&head[0], 1, head.size(), f));
  std::fclose(f);
  return isContainerFormat(containerMagic(head));
}

Format detectFormat(const std::string& path) {
  if (isDir(path)) {
    if (!isSequenceDirectory(path))
      throw IoError(path + ": directory without " + sequence_file::kEvents + " (expected the RPG / UZH-FPV layout)");
    return Format::RpgDirectory;
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw IoError(path + ": cannot open: " + std::strerror(errno));
  // The header decides: the AEDAT magic line, else the first 4 KB must look like
  // text (no control bytes but tab / CR / LF / FF, valid UTF-8).
  std::string head(4096, '\0');
  head.resize(std::fread(&head[0], 1, head.size(), f));
  std::fclose(f);
  if (head.rfind("#!AER-DAT2.0", 0) == 0) return Format::Aedat2;
  if (head.rfind("#!AER-DAT3.1", 0) == 0) return Format::Aedat31;
  if (head.rfind("#!AER-DAT4.0", 0) == 0) return Format::Aedat4;
  if (const Format c = containerMagic(head); isContainerFormat(c)) return c;
  if (head.rfind("#!AER-DAT", 0) == 0) {
    const std::size_t eol = head.find_first_of("\r\n");
    throw IoError(path + ": byte 0: unsupported AEDAT version '" +
                  detail::printable(head.substr(0, std::min<std::size_t>(eol, 24)), 24) + "'");
  }
  const std::size_t bad = detail::firstNonTextByte(head);
  if (bad != std::string::npos) {
    char b[8];
    std::snprintf(b, sizeof b, "0x%02X", unsigned(static_cast<unsigned char>(head[bad])));
    throw IoError(path + ": byte " + std::to_string(bad) + ": binary data (byte " + b +
                  ") without an AEDAT magic line: not an events text file");
  }
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
    case Format::RosBag: return detail::openRosBag(path, options);
    case Format::Hdf5: return detail::openHdf5(path, options);
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
  if (isContainerFormat(info.format)) {
    const auto poses = reader->readPoses();
    if (!poses.empty()) {
      char line[160];
      std::snprintf(line, sizeof line, "ground-truth poses: %zu in [%.6f, %.6f] s", poses.size(), poses.front().t,
                    poses.back().t);
      info.notes.push_back(line);
    }
  }
  const auto imu = reader->readImu();
  info.imu_samples = imu.size();
  if (!imu.empty()) {
    info.imu_t_first = imu.front().t;
    info.imu_t_last = imu.back().t;
  }
  return info;
}

}  // namespace celc
