#pragma once
/// \file event_reader.hpp
/// Streaming readers for event-camera recordings. Every reader yields events as
/// (t [s], x, y [px, origin top-left, x right, y down], polarity) and IMU samples
/// (t [s], gyro [rad/s], accel [m/s^2]) in the sensor's own IMU frame, whatever
/// the units of the file.
///
/// Formats: RPG / Event Camera Dataset / UZH-FPV text (a directory holding
/// events.txt [+ imu.txt], or a single events text file), AEDAT 2.0 (jAER,
/// DAVIS), AEDAT 3.1 (cAER), AEDAT 4.0 (DV), ROS 1 bags (format 2.0 and 1.2;
/// dvs_msgs/EventArray, sensor_msgs/Imu, geometry_msgs/PoseStamped or
/// nav_msgs/Odometry, sensor_msgs/CameraInfo) and HDF5 (the DSEC and MVSEC
/// layouts). openEventSource() detects the format from the magic bytes
/// (`#!AER-DAT2.0`, `#!AER-DAT3.1`, `#!AER-DAT4.0`, `#ROSBAG V`, the HDF5 signature).
///
/// Bad-input policy (docs/formats.md):
///  - errors (an IoError naming the file and the line or byte offset): bad magic,
///    truncated binary records, sizes or offsets out of range, corrupt
///    compression or flatbuffers, non-numeric text fields, wrong column counts;
///  - counted warnings: timestamps going backwards within a tolerance (event
///    kept), single outlier timestamps (dropped) and gaps (kept), pixels outside
///    the sensor (event dropped; an error past a share), unknown AEDAT event
///    types (skipped), a truncated final packet or record (the complete ones
///    are read). With ReaderOptions::strict, a warning is an error too.
///  - time sanity (every format, the same rules; see EventReader::admit):
///    decreases beyond ReaderOptions::backwards_tolerance below the latest time
///    so far are an error (or are dropped / sorted when asked), forward jumps
///    beyond max_time_jump are an outlier when the next event comes back, a gap
///    when it does not; a first event more than max_time_jump after the ones
///    that follow is an outlier too.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <queue>
#include <stdexcept>
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc {

/// Thrown at the I/O boundary; what() is one line: "FILE: line N: ..." or "FILE: byte N: ...".
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Format { Text, RpgDirectory, Aedat2, Aedat31, Aedat4, RosBag, Hdf5 };
std::string toString(Format format);

/// Column order of an IMU text file (when the file has no header naming them).
enum class ImuColumns {
  Auto,         ///< from a `#` header line naming the columns, else RPG order
  RpgAccelFirst,  ///< t ax ay az gx gy gz (Event Camera Dataset imu.txt)
  GyroFirst,    ///< t wx wy wz ax ay az (UZH-FPV; a leading id column is detected by count)
};
ImuColumns parseImuColumns(const std::string& name);  ///< "auto" | "rpg" | "gyro_first"
std::string toString(ImuColumns columns);             ///< "auto" | "rpg" | "gyro_first"

/// What a reader does with an event whose timestamp is more than
/// ReaderOptions::backwards_tolerance before the latest earlier time (the running maximum).
enum class BackwardsPolicy {
  Error,  ///< stop with an error naming the line / byte (the default: the file is not time-ordered)
  Drop,   ///< drop the event, counted as a warning
  Sort,   ///< reorder through a buffer of kSortBufferEvents events, counted as a warning
};
std::string toString(BackwardsPolicy policy);  ///< "error" | "drop" | "sort"

/// Largest sensor side [px] any reader accepts from a file or an option: the
/// undistortion table holds one entry per pixel, so a hostile header must not
/// size it (celc::kMaxSensorSide in geometry/undistort.hpp is the same bound).
inline constexpr int kMaxReaderSensorSide = 4096;
/// Binary formats store integer microseconds; the library holds double
/// seconds, whose spacing is at most 2^-20 s (< 1 us) below 2^33 s (272 years).
/// A time at or beyond this bound [us] is an error naming its place, never
/// rounded silently to milliseconds.
inline constexpr std::int64_t kMaxExactMicroseconds = std::int64_t(8589934592) * 1000000;
/// Events held by BackwardsPolicy::Sort (a bounded reorder buffer).
inline constexpr std::size_t kSortBufferEvents = std::size_t(1) << 20;

struct ReaderOptions {
  /// Out of line: it keeps GCC 12 from a false -Wmaybe-uninitialized on the
  /// topic strings of a value-initialised temporary holding these options.
  ReaderOptions();
  /// Sensor size [px] when the file does not say (text formats); 0 = unknown:
  /// no pixel-range check. A non-zero value overrides the size in the file.
  int width = 0;
  int height = 0;
  ImuColumns imu_columns = ImuColumns::Auto;
  /// Text timestamps are multiplied by this to give seconds (1 for seconds, 1e-6 for us, 1e-9 for ns).
  double text_time_scale = 1.0;
  /// Turn every counted warning into an error.
  bool strict = false;
  /// Upper bound of one decoded AEDAT packet [bytes]: a hostile size beyond it is an error.
  std::size_t max_packet_bytes = std::size_t(64) << 20;
  /// AEDAT 3.1: read only this source id (-1 = every source, merged in file order).
  int aedat_source = -1;
  /// Largest plausible forward step between consecutive events [s]. One event
  /// beyond it followed by one back near the previous time is an outlier
  /// (dropped, counted); a jump the next event confirms is a gap (kept, counted).
  double max_time_jump = 10.0;
  /// Decreases of the timestamp below the latest time so far up to this [s]
  /// are counted and the event kept; larger ones follow `backwards`. Measured
  /// from the running maximum, so small steps back add up.
  double backwards_tolerance = 1e-3;
  BackwardsPolicy backwards = BackwardsPolicy::Error;
  /// Share of events with a pixel outside the sensor beyond which reading stops
  /// with an error (checked once 100 such events are seen): a wrong sensor size.
  double max_outside_share = 0.05;
  /// ROS bag topics (empty = found by message type: the one topic of
  /// dvs_msgs/EventArray, of sensor_msgs/Imu, of geometry_msgs/PoseStamped or
  /// nav_msgs/Odometry; several candidates are an error naming them).
  std::string topic_events;
  std::string topic_imu;
  std::string topic_pose;
  /// Empty when valid, else what is wrong.
  std::string validate() const;
};
/// The schema of the `input:` section (core/fields.hpp).
void describe(FieldVisitor& v, ReaderOptions& options);


/// Counted warnings (first few messages kept verbatim).
struct ReaderWarnings {
  std::uint64_t backwards_time = 0;   ///< timestamp smaller than the previous event's (kept)
  std::uint64_t outside_sensor = 0;   ///< pixel outside [0,width)x[0,height) (dropped)
  std::uint64_t skipped_records = 0;  ///< unknown event types / special events skipped
  std::uint64_t time_jumps = 0;       ///< outlier timestamps dropped and gaps beyond max_time_jump
  std::uint64_t truncated = 0;        ///< a final packet / record cut by the end of the file
  // Breakdowns of the counts above (not added again by total()):
  std::uint64_t backwards_sorted = 0;   ///< of backwards_time: beyond the tolerance, reordered (input.backwards: sort)
  std::uint64_t backwards_dropped = 0;  ///< of backwards_time: dropped (input.backwards: drop; too late for the sort buffer)
  std::uint64_t time_outliers = 0;      ///< of time_jumps: single outlier timestamps dropped (the others: gaps, kept)
  std::uint64_t truncated_at = 0;       ///< with `truncated`: the byte where the file ends
  std::vector<std::string> messages;  ///< up to 20 first messages
  std::uint64_t total() const {
    return backwards_time + outside_sensor + skipped_records + time_jumps + truncated;
  }
};

/// Pull reader: events in file order, IMU on request.
class EventReader {
 public:
  virtual ~EventReader() = default;
  virtual Format format() const = 0;
  /// The event source path (a file; for a directory its events file).
  const std::string& path() const { return path_; }
  /// Sensor size [px]; 0 when unknown.
  int width() const { return width_; }
  int height() const { return height_; }
  /// Clears `batch` and fills it with up to `max` next events (max >= 1).
  /// Returns false when the stream is exhausted (then batch is empty).
  virtual bool next(std::vector<Event>& batch, std::size_t max) = 0;
  /// Every IMU sample of the recording (a separate pass; independent of next()).
  /// Empty when the source has none.
  virtual std::vector<ImuSample> readImu() = 0;
  /// Number of IMU samples without keeping them (default: readImu().size()).
  virtual std::uint64_t countImu() { return readImu().size(); }
  /// Ground-truth poses T_world_body stored with the events (ROS bag pose
  /// topic, MVSEC davis/left/pose), in time order; empty when the source has none.
  virtual std::vector<PoseSample> readPoses() { return {}; }
  /// Skips ahead so that the next event read is the first with t >= t_start [s]
  /// (some earlier events of the same packet may remain; callers filter).
  /// Returns false when the reader cannot seek (then nothing changes).
  virtual bool seekTime(double t_start) { (void)t_start; return false; }
  /// The options the reader was opened with.
  const ReaderOptions& options() const { return options_; }
  /// Warnings counted so far by next().
  const ReaderWarnings& warnings() const { return warnings_; }
  /// Human-readable notes about the source (chip name, compression, streams...).
  const std::vector<std::string>& notes() const { return notes_; }
  void addNote(const std::string& note) { notes_.push_back(note); }

 protected:
  /// Counts a warning and keeps its message (printable, one line); with
  /// `strict` it is an IoError instead.
  void warn(std::uint64_t ReaderWarnings::*counter, const std::string& message);
  /// A record or packet cut by the end of the file at byte `file_end`: counted
  /// in `truncated` with that byte kept (an error with `strict`).
  void warnTruncated(std::uint64_t file_end, const std::string& message);
  /// An event whose pixel is outside the sensor: counted; an IoError once more
  /// than max_outside_share of the events read are outside. `where` is
  /// "FILE: line N" / "FILE: byte N".
  void outsideSensor(const std::string& where, double x, double y);

  /// Passes one decoded event through the time checks into `out` (every reader
  /// calls it instead of push_back). `where()` gives "FILE: line N" or
  /// "FILE: byte N" and is only called when something is reported. Events may
  /// be held back (an outlier candidate, the sort buffer): release() them at
  /// the end of the stream.
  template <class Where>
  void admit(std::vector<Event>& out, const Event& e, Where&& where) {
    ++admitted_;
    if (have_prev_ && !holding_ && reorder_.empty() && out.size() < batch_max_ && e.t >= prev_t_ &&
        e.t - prev_t_ <= options_.max_time_jump) {
      prev_t_ = e.t;
      out.push_back(e);
      return;
    }
    admitSlow(out, e, where());
  }
  /// At the end of the stream: moves held events into `out` (at most up to
  /// `max` events in `out`). Readers call it when a batch comes out short.
  void release(std::vector<Event>& out, std::size_t max);
  /// Every next() starts with it: clears `batch`, puts in it the events that
  /// a held event released beyond the previous batch's `max`, and returns max
  /// (at least 1). A batch therefore never holds more than `max` events.
  std::size_t startBatch(std::vector<Event>& batch, std::size_t max);

  std::string path_;
  int width_ = 0, height_ = 0;
  ReaderOptions options_;
  ReaderWarnings warnings_;
  std::vector<std::string> notes_;

 private:
  struct Later {
    bool operator()(const Event& a, const Event& b) const { return a.t > b.t; }
  };
  void admitSlow(std::vector<Event>& out, const Event& e, const std::string& where);
  /// The first events: the first is held until the next one; one more than
  /// max_time_jump before it is held too, and the third decides which of the
  /// two is an outlier (dropped, counted). True when `e` was held.
  bool admitStart(std::vector<Event>& out, const Event& e, const std::string& where);
  enum class Start { None, First, Second, Done };
  Start start_ = Start::None;
  Event first_{}, second_{};
  std::string first_where_, second_where_;
  void accept(std::vector<Event>& out, const Event& e);
  bool have_prev_ = false;
  double prev_t_ = 0.0;        ///< latest time passed on (or pushed to the sort buffer); decreases are measured from it
  bool holding_ = false;       ///< `held_` is an outlier candidate (a forward jump)
  Event held_{};
  std::string held_where_;
  std::uint64_t admitted_ = 0;  ///< events offered to admit() (for the outside share)
  std::priority_queue<Event, std::vector<Event>, Later> reorder_;
  std::size_t batch_max_ = std::size_t(-1);  ///< the current batch's max (startBatch)
  std::vector<Event> ready_;                  ///< passed events beyond batch_max_, for the next batch
  bool emitted_any_ = false;
  double last_emitted_ = 0.0;  ///< sort mode: time of the last event released from the buffer
};

namespace detail {
/// `s` as printable ASCII on one line, at most `max` characters of it: control
/// bytes, bytes >= 0x7F (invalid UTF-8 included) become \xNN, a cut is marked
/// "...". Every fragment of an input file echoed in a message goes through it.
std::string printable(const std::string& s, std::size_t max = 80);
/// Offset of the first byte that is not text (a control byte other than tab /
/// CR / LF / FF, or invalid UTF-8), npos when none (a cut sequence at the end is text).
std::size_t firstNonTextByte(const std::string& s);
}  // namespace detail

/// Detects the format (directory in RPG/UZH-FPV layout, `#!AER-DAT` magic,
/// else a text events file) and opens a reader. Throws IoError.
std::unique_ptr<EventReader> openEventSource(const std::string& path,
                                             const ReaderOptions& options = {});
/// Format of a path without opening a reader. Throws IoError when unreadable.
Format detectFormat(const std::string& path);
/// True for the container formats that carry IMU, poses and (bags) the camera
/// calibration besides the events: ROS bag and HDF5.
bool isContainerFormat(Format format);
/// True when `path` is a regular file that starts like a ROS bag or an HDF5
/// file (its magic bytes only; never throws).
bool isContainerFile(const std::string& path);

/// A summary from one full pass (what `celc info` prints).
struct FileInfo {
  Format format = Format::Text;
  std::string path;
  int width = 0, height = 0;      ///< sensor size [px] (0 = unknown)
  int max_x = -1, max_y = -1;     ///< largest pixel coordinates seen
  std::uint64_t events = 0;
  std::uint64_t on_events = 0;
  double t_first = 0.0, t_last = 0.0;  ///< first / last event time [s] (file order)
  double t_min = 0.0, t_max = 0.0;     ///< min / max event time [s]
  std::uint64_t imu_samples = 0;
  double imu_t_first = 0.0, imu_t_last = 0.0;
  ReaderWarnings warnings;
  std::vector<std::string> notes;
  double duration() const { return events > 1 ? t_max - t_min : 0.0; }
  double eventRate() const { return duration() > 0 ? double(events) / duration() : 0.0; }
  double imuRate() const {
    return imu_samples > 1 && imu_t_last > imu_t_first
               ? double(imu_samples - 1) / (imu_t_last - imu_t_first) : 0.0;
  }
};
/// One full pass over the source (events streamed in batches, IMU counted).
FileInfo scanFile(const std::string& path, const ReaderOptions& options = {});

/// Reads all events of a source (convenience for small files and tests).
std::vector<Event> readAllEvents(EventReader& reader);

}  // namespace celc
