#include "celc/io/text_io.hpp"


#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "io/text_parse.hpp"

namespace celc {
namespace {

using detail::LineReader;

constexpr std::size_t kMaxCols = 16;

bool nameIs(const std::string& n, std::initializer_list<const char*> names) {
  for (const char* s : names)
    if (n == s) return true;
  return false;
}

/// Column layout: index of each required field, and the expected column count.
struct Layout {
  std::vector<int> idx;
  std::size_t ncols = 0;
  bool known = false;
};

/// Maps header names to fields through `classify` (field index or -1); a header
/// is accepted only when every field is found.
template <typename Classify>
bool layoutFromHeader(std::string_view line, std::size_t nfields, Classify classify, Layout& out) {
  auto names = detail::headerNames(line);
  if (names.size() < nfields || names.size() > kMaxCols) return false;
  std::vector<int> idx(nfields, -1);
  for (std::size_t c = 0; c < names.size(); ++c) {
    int f = classify(names[c]);
    if (f >= 0 && idx[std::size_t(f)] < 0) idx[std::size_t(f)] = int(c);
  }
  for (int i : idx)
    if (i < 0) return false;
  out.idx = idx;
  out.ncols = names.size();
  out.known = true;
  return true;
}

int classifyEvent(const std::string& n) {
  if (nameIs(n, {"t", "ts", "time", "timestamp", "timestamps", "t[s]", "time[s]", "timestamp[s]"})) return 0;
  if (nameIs(n, {"x", "u"})) return 1;
  if (nameIs(n, {"y", "v"})) return 2;
  if (nameIs(n, {"p", "pol", "polarity", "on"})) return 3;
  return -1;
}

// IMU fields: 0 t, 1..3 gyro, 4..6 accel.
int classifyImu(const std::string& n) {
  if (nameIs(n, {"t", "ts", "time", "timestamp", "timestamps"})) return 0;
  static const char* axes = "xyz";
  for (int a = 0; a < 3; ++a) {
    const std::string x(1, axes[a]);
    if (n == "g" + x || n == "w" + x || n == "gyro_" + x || n == "gyr_" + x ||
        n == "ang_vel_" + x || n == "angular_velocity_" + x || n == "omega_" + x || n == "w_" + x ||
        n == "gyroscope_" + x || n == "g_" + x)
      return 1 + a;
    if (n == "a" + x || n == "acc_" + x || n == "accel_" + x || n == "lin_acc_" + x ||
        n == "linear_acceleration_" + x || n == "a_" + x || n == "accelerometer_" + x)
      return 4 + a;
  }
  return -1;
}

// Pose fields: 0 t, 1..3 position, 4..7 qx qy qz qw.
int classifyPose(const std::string& n) {
  if (nameIs(n, {"t", "ts", "time", "timestamp", "timestamps"})) return 0;
  if (nameIs(n, {"px", "tx", "x", "p_x", "pos_x", "position_x"})) return 1;
  if (nameIs(n, {"py", "ty", "y", "p_y", "pos_y", "position_y"})) return 2;
  if (nameIs(n, {"pz", "tz", "z", "p_z", "pos_z", "position_z"})) return 3;
  if (nameIs(n, {"qx", "q_x", "quat_x", "orientation_x"})) return 4;
  if (nameIs(n, {"qy", "q_y", "quat_y", "orientation_y"})) return 5;
  if (nameIs(n, {"qz", "q_z", "quat_z", "orientation_z"})) return 6;
  if (nameIs(n, {"qw", "q_w", "quat_w", "orientation_w"})) return 7;
  return -1;
}

/// Shared line loop: skips comments / blank lines, takes a header when one
/// names all fields, else fixes the layout from the first data line's column
/// count through `byCount` (returns false for an unsupported count).
template <typename Classify, typename ByCount>
bool nextRecord(LineReader& lr, Layout& layout, std::size_t nfields, Classify classify,
                ByCount byCount, std::array<std::string_view, kMaxCols>& fields,
                std::size_t& nfound) {
  std::string_view line;
  while (lr.next(line)) {
    std::size_t i = 0;
    while (i < line.size() && detail::isSpace(line[i])) ++i;
    if (i == line.size()) continue;
    if (line[i] == '#' || line[i] == '%') {
      if (!layout.known) layoutFromHeader(line.substr(i), nfields, classify, layout);
      continue;
    }
    if (!layout.known && detail::looksLikeHeader(line)) {
      if (!layoutFromHeader(line, nfields, classify, layout))
        lr.fail("header line does not name the expected columns: '" +
                std::string(line.substr(0, 80)) + "'");
      continue;
    }
    nfound = detail::splitFields(line, fields.data(), kMaxCols);
    // A file with CR-only line endings (classic Mac) reads as one long line.
    if (const std::size_t cr = line.find('\r'); cr != std::string_view::npos && cr + 1 < line.size() &&
                                                 line.find_first_not_of(" \t\r", cr) != std::string_view::npos)
      lr.fail("line endings are CR only (\\r without \\n): convert them to \\n, e.g. tr '\\r' '\\n'");
    if (!layout.known) {
      if (nfound > kMaxCols || !byCount(nfound, layout))
        lr.fail("unsupported column count " +
                (nfound > kMaxCols ? std::string("> 16") : std::to_string(nfound)));
      layout.ncols = nfound;
      layout.known = true;
    }
    if (nfound != layout.ncols)
      lr.fail("expected " + std::to_string(layout.ncols) + " columns, found " +
              (nfound > kMaxCols ? std::string("> 16") : std::to_string(nfound)));
    return true;
  }
  return false;
}

double field(LineReader& lr, const std::array<std::string_view, kMaxCols>& f, int col,
             const char* what) {
  double v;
  if (!detail::parseDouble(f[std::size_t(col)], v) || !std::isfinite(v))
    lr.fail(std::string("non-numeric ") + what + " '" + std::string(f[std::size_t(col)].substr(0, 40)) +
            "' in column " + std::to_string(col + 1));
  return v;
}

class TextEventReader final : public EventReader {
 public:
  TextEventReader(const std::string& events, const std::string& imu, const ReaderOptions& o)
      : lr_(events), imu_path_(imu) {
    path_ = events;
    options_ = o;
    width_ = o.width;
    height_ = o.height;
  }
  Format format() const override { return Format::Text; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    auto byCount = [](std::size_t n, Layout& l) {
      if (n == 4) l.idx = {0, 1, 2, 3};
      else if (n == 5) l.idx = {1, 2, 3, 4};
      else return false;
      return true;
    };
    std::array<std::string_view, kMaxCols> f;
    std::size_t n = 0;
    while (batch.size() < max &&
           nextRecord(lr_, layout_, 4, classifyEvent, byCount, f, n)) {
      Event e;
      double t = field(lr_, f, layout_.idx[0], "timestamp") * options_.text_time_scale;
      long long xi, yi, pi;
      double xd, yd;
      if (detail::parseInt(f[std::size_t(layout_.idx[1])], xi)) xd = double(xi);
      else xd = field(lr_, f, layout_.idx[1], "x");
      if (detail::parseInt(f[std::size_t(layout_.idx[2])], yi)) yd = double(yi);
      else yd = field(lr_, f, layout_.idx[2], "y");
      if (!detail::parseInt(f[std::size_t(layout_.idx[3])], pi) || (pi != 0 && pi != 1 && pi != -1))
        lr_.fail("polarity must be 0, 1 or -1, found '" +
                 std::string(f[std::size_t(layout_.idx[3])].substr(0, 40)) + "'");
      e.t = t;
      e.x = float(xd);
      e.y = float(yd);
      e.on = pi == 1;
      if (options_.text_time_scale == 1.0 && scale_checked_ < kScaleProbe) checkTimeScale(t);
      // without a sensor size, 65536 bounds any sensor (and keeps integer conversions defined)
      const double wmax = width_ > 0 ? width_ : 65536.0, hmax = height_ > 0 ? height_ : 65536.0;
      if (!(xd >= 0 && yd >= 0 && xd < wmax && yd < hmax)) {
        outsideSensor(where(), xd, yd);
        continue;
      }
      admit(batch, e, [this] { return where(); });
    }
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    if (imu_path_.empty()) return {};
    return readImuText(imu_path_, options_);
  }

 private:
  static constexpr int kScaleProbe = 64;
  std::string where() const { return path_ + ": line " + std::to_string(lr_.lineNumber()); }
  /// Seconds are what the file should hold: the first kScaleProbe timestamps all
  /// whole numbers at least 1 apart on average are microseconds (or
  /// nanoseconds) read as seconds, an error that names input.time_scale.
  void checkTimeScale(double t) {
    if (scale_checked_ == 0) scale_first_ = t;
    scale_integers_ = scale_integers_ && t == std::floor(t);
    if (++scale_checked_ < kScaleProbe || !scale_integers_) return;
    const double step = (t - scale_first_) / double(kScaleProbe - 1);
    if (step >= 1.0) {
      char msg[200];
      std::snprintf(msg, sizeof msg,
                    "the first %d timestamps are whole numbers %.4g apart on average: microseconds or "
                    "nanoseconds read as seconds? set input.time_scale (--time-scale 1e-6 for us, 1e-9 for ns)",
                    kScaleProbe, step);
      lr_.fail(msg);
    }
  }
  LineReader lr_;
  std::string imu_path_;
  Layout layout_;
  int scale_checked_ = 0;
  bool scale_integers_ = true;
  double scale_first_ = 0.0;
};

}  // namespace

std::unique_ptr<EventReader> openTextEvents(const std::string& events_path,
                                            const std::string& imu_path,
                                            const ReaderOptions& options) {
  std::string err = options.validate();
  if (!err.empty()) throw IoError(events_path + ": invalid reader options: " + err);
  return std::make_unique<TextEventReader>(events_path, imu_path, options);
}

std::vector<ImuSample> readImuText(const std::string& path, const ReaderOptions& options) {
  LineReader lr(path);
  Layout layout;
  const bool gyro_first_opt = options.imu_columns == ImuColumns::GyroFirst;
  const bool rpg_opt = options.imu_columns == ImuColumns::RpgAccelFirst;
  auto byCount = [&](std::size_t n, Layout& l) {
    int off;
    bool gyro_first;
    if (n == 7) off = 0, gyro_first = gyro_first_opt;
    else if (n == 8) off = 1, gyro_first = !rpg_opt;  // UZH-FPV: id t wx wy wz ax ay az
    else return false;
    if (gyro_first) l.idx = {off, off + 1, off + 2, off + 3, off + 4, off + 5, off + 6};
    else l.idx = {off, off + 4, off + 5, off + 6, off + 1, off + 2, off + 3};
    return true;
  };
  std::vector<ImuSample> out;
  std::array<std::string_view, kMaxCols> f;
  std::size_t n = 0;
  static const char* names[7] = {"timestamp", "gyro x", "gyro y", "gyro z", "accel x", "accel y", "accel z"};
  while (nextRecord(lr, layout, 7, classifyImu, byCount, f, n)) {
    ImuSample s;
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = field(lr, f, layout.idx[std::size_t(i)], names[i]);
    s.t = v[0] * options.text_time_scale;
    s.gyro = Vec3(v[1], v[2], v[3]);
    s.accel = Vec3(v[4], v[5], v[6]);
    if (!out.empty() && s.t < out.back().t) {
      if (options.strict) lr.fail("IMU timestamp goes backwards");
      // keep sorted: IMU consumers need monotonic time; drop the sample
      continue;
    }
    out.push_back(s);
  }
  return out;
}

std::vector<PoseSample> readPosesText(const std::string& path, const ReaderOptions& options) {
  if (isContainerFile(path)) {
    // A ROS bag or HDF5 file named as the ground truth: its pose topic / dataset.
    std::vector<PoseSample> poses = openEventSource(path, options)->readPoses();
    for (std::size_t i = 1; i < poses.size(); ++i)
      if (!(poses[i].t > poses[i - 1].t))
        throw IoError(path + ": pose " + std::to_string(i) + ": pose timestamps must increase (" +
                      std::to_string(poses[i].t) + " after " + std::to_string(poses[i - 1].t) + ")");
    return poses;
  }
  LineReader lr(path);
  Layout layout;
  auto byCount = [](std::size_t n, Layout& l) {
    int off;
    if (n == 8) off = 0;
    else if (n == 9) off = 1;
    else return false;
    l.idx = {off, off + 1, off + 2, off + 3, off + 4, off + 5, off + 6, off + 7};
    return true;
  };
  std::vector<PoseSample> out;
  std::array<std::string_view, kMaxCols> f;
  std::size_t n = 0;
  static const char* names[8] = {"timestamp", "px", "py", "pz", "qx", "qy", "qz", "qw"};
  while (nextRecord(lr, layout, 8, classifyPose, byCount, f, n)) {
    double v[8];
    for (int i = 0; i < 8; ++i) v[i] = field(lr, f, layout.idx[std::size_t(i)], names[i]);
    PoseSample p;
    p.t = v[0] * options.text_time_scale;
    p.position = Vec3(v[1], v[2], v[3]);
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-9) lr.fail("zero quaternion");
    p.orientation = q.normalized();
    if (!out.empty() && p.t <= out.back().t)
      lr.fail("pose timestamps must increase (" + std::to_string(p.t) + " after " +
              std::to_string(out.back().t) + ")");
    out.push_back(p);
  }
  return out;
}

}  // namespace celc
