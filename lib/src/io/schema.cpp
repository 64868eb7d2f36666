// The schema of the io module's options (core/fields.hpp).
#include "celc/io/event_reader.hpp"
#include "celc/io/imu_window.hpp"
#include "celc/io/window_source.hpp"

namespace celc {

void describe(FieldVisitor& v, ReaderOptions& o) {
  v.field({"width", "px",
           "sensor width when the file does not say (0 = unknown)",
           within(0, kMaxReaderSensorSide)},
          o.width);
  v.field({"height", "px",
           "sensor height when the file does not say (0 = unknown)",
           within(0, kMaxReaderSensorSide)},
          o.height);
  v.enumeration({"imu_columns", "", "column order of an IMU text file without a header"}, o.imu_columns,
                {ImuColumns::Auto, ImuColumns::RpgAccelFirst, ImuColumns::GyroFirst});
  v.field({"time_scale", "s/unit", "text timestamps times this give seconds (1e-6 for us)", above(0)},
          o.text_time_scale);
  v.field({"strict", "", "every counted warning is an error"}, o.strict);
  v.field({"max_packet_bytes", "bytes", "largest AEDAT packet decoded", atLeast(1024)}, o.max_packet_bytes);
  v.field({"aedat_source", "", "AEDAT 3.1: only this source id (-1 = all)", within(-1, 32767)}, o.aedat_source);
  v.field({"max_time_jump", "s",
           "larger forward steps between events: one outlier dropped, or a gap (reported)",
           above(0)},
          o.max_time_jump);
  v.field({"backwards_tolerance", "s",
           "timestamp decreases below the latest time so far up to this are counted and kept",
           atLeast(0)},
          o.backwards_tolerance);
  v.enumeration({"backwards", "", "larger decreases: error, drop the event, or sort (bounded buffer)"},
                o.backwards, {BackwardsPolicy::Error, BackwardsPolicy::Drop, BackwardsPolicy::Sort});
  v.field({"max_outside_share", "-", "share of events outside the sensor that stops the reading", within(0, 1)},
          o.max_outside_share);
  v.field({"topic_events", "", "ROS bag events topic, dvs_msgs/EventArray (empty = the one such topic)"},
          o.topic_events);
  v.field({"topic_imu", "", "ROS bag IMU topic, sensor_msgs/Imu (empty = the one such topic)"}, o.topic_imu);
  v.field({"topic_pose", "",
           "ROS bag ground-truth topic, geometry_msgs/PoseStamped or nav_msgs/Odometry (empty = the one such topic)"},
          o.topic_pose);
}

void describe(FieldVisitor& v, WindowOptions& o) {
  v.field({"events", "events", "events per window (policy events; 0 otherwise)"}, o.events_per_window);
  v.field({"seconds", "s", "window length (policy seconds; 0 otherwise)"}, o.seconds_per_window);
  v.field({"overlap", "-", "share of a window overlapping the next, in [0, 1)", withinBelow(0, 1)}, o.overlap);
  v.field({"t_start", "s", "first time used"}, o.t_start);
  v.field({"t_end", "s", "end of the time used (exclusive)"}, o.t_end);
  v.field({"read_batch", "events", "events pulled from the reader at a time", atLeast(1)}, o.read_batch);
  v.field({"keep_partial", "", "also emit the last, incomplete window, whatever it holds"}, o.keep_partial);
  v.field({"partial_min_share", "-",
           "otherwise the last, incomplete window is processed when it holds this share of a window, in [0, 1]",
           within(0, 1)},
          o.partial_min_share);
  v.field({"max_windows_per_second", "1/s",
           "a window policy making more windows per second of data is an error",
           above(0)},
          o.max_windows_per_second);
  v.field({"max_events", "events", "a window that would hold more events is an error naming its time", atLeast(1)},
          o.max_events);
}

void describe(FieldVisitor& v, GyroWindowOptions& o) {
  v.field({"gyro_max_gap", "s", "largest gap between gyro samples inside a window", above(0)}, o.max_gap);
}

}  // namespace celc
