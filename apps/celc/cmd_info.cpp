// `celc info FILE|DIR`: what an event recording holds.
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "celc/io/event_reader.hpp"
#include "celc/pipeline/imu_still.hpp"
#include "celc/pipeline/run_config.hpp"
#include "commands.hpp"

namespace celc::app {

namespace {
struct InfoArgs {
  std::string path;
  int width = 0, height = 0;
  std::string imu_columns = "auto";
  double time_scale = 1.0;
  bool strict = false;
  std::string backwards = "error";
  double max_time_jump = ReaderOptions().max_time_jump;
  std::string topic_events, topic_imu, topic_pose;
};

int runInfo(const InfoArgs& a) {
  ReaderOptions o;
  o.width = a.width;
  o.height = a.height;
  o.imu_columns = parseImuColumns(a.imu_columns);
  o.text_time_scale = a.time_scale;
  o.strict = a.strict;
  o.backwards = a.backwards == "sort" ? BackwardsPolicy::Sort
                : a.backwards == "drop" ? BackwardsPolicy::Drop : BackwardsPolicy::Error;
  o.max_time_jump = a.max_time_jump;
  o.topic_events = a.topic_events;
  o.topic_imu = a.topic_imu;
  o.topic_pose = a.topic_pose;
  const FileInfo info = scanFile(a.path, o);
  std::printf("file:          %s\n", info.path.c_str());
  std::printf("format:        %s\n", toString(info.format).c_str());
  if (info.width > 0)
    std::printf("sensor:        %d x %d px\n", info.width, info.height);
  else
    std::printf("sensor:        unknown (pixels seen up to x=%d, y=%d)\n", info.max_x, info.max_y);
  for (const auto& n : info.notes) std::printf("note:          %s\n", n.c_str());
  std::printf("events:        %llu\n", static_cast<unsigned long long>(info.events));
  if (info.events > 0) {
    std::printf("ON share:      %.4f (%llu ON)\n", double(info.on_events) / double(info.events),
                static_cast<unsigned long long>(info.on_events));
    std::printf("time range:    [%.6f, %.6f] s\n", info.t_min, info.t_max);
    std::printf("duration:      %.6f s\n", info.duration());
    std::printf("event rate:    %.4g events/s\n", info.eventRate());
  }
  std::printf("IMU samples:   %llu\n", static_cast<unsigned long long>(info.imu_samples));
  if (info.imu_samples > 0) {
    std::printf("IMU range:     [%.6f, %.6f] s\n", info.imu_t_first, info.imu_t_last);
    std::printf("IMU rate:      %.2f Hz\n", info.imuRate());
    // The first still second: its mean gyro rate estimates motion.gyro_bias.
    try {
      const StillSpan still = findFirstStill(openEventSource(a.path, o)->readImu());
      if (still.found)
        std::printf("gyro at rest:  mean %.6f,%.6f,%.6f rad/s (IMU frame; |mean| %.2f deg/s; std %.4f,%.4f,%.4f; "
                    "accelerometer direction turns %.4f rad) over the first still second [%.3f, %.3f] s: an "
                    "estimate of motion.gyro_bias%s\n",
                    still.gyro_mean.x(), still.gyro_mean.y(), still.gyro_mean.z(),
                    still.gyro_mean.norm() * 180.0 / M_PI, still.gyro_std.x(), still.gyro_std.y(),
                    still.gyro_std.z(), still.accel_turn, still.t0, still.t1,
                    still.significant(kStillBiasZ, kStillBiasMinRate)
                        ? " (significant: celc run subtracts it by default)"
                        : " (within the noise: celc run leaves it by default)");
      else
        std::printf("gyro at rest:  no still second (%s)\n", still.refused.c_str());
      if (!still.warning.empty()) std::printf("gyro warning:  %s\n", still.warning.c_str());
    } catch (const std::exception& e) {
      spdlog::warn("IMU not read for the still-second check: {}", e.what());
    }
  }
  std::printf("warnings:      %llu (timestamps backwards %llu, pixels outside sensor %llu, skipped %llu, "
              "time jumps and gaps %llu, truncated end %llu)\n",
              static_cast<unsigned long long>(info.warnings.total()),
              static_cast<unsigned long long>(info.warnings.backwards_time),
              static_cast<unsigned long long>(info.warnings.outside_sensor),
              static_cast<unsigned long long>(info.warnings.skipped_records),
              static_cast<unsigned long long>(info.warnings.time_jumps),
              static_cast<unsigned long long>(info.warnings.truncated));
  // The same counts, one line each, with their breakdowns.
  const ReaderWarnings& w = info.warnings;
  const auto u = [](std::uint64_t n) { return static_cast<unsigned long long>(n); };
  std::printf("time jumps:    %llu (outliers dropped %llu, gaps kept %llu; input.max_time_jump = %g s)\n",
              u(w.time_jumps), u(w.time_outliers), u(w.time_jumps - w.time_outliers), o.max_time_jump);
  std::printf("backwards:     %llu (kept within input.backwards_tolerance %llu, sorted %llu, dropped %llu)\n",
              u(w.backwards_time), u(w.backwards_time - w.backwards_sorted - w.backwards_dropped),
              u(w.backwards_sorted), u(w.backwards_dropped));
  std::printf("outside:       %llu events with a pixel outside the sensor (dropped)\n", u(w.outside_sensor));
  if (w.truncated > 0)
    std::printf("truncated:     yes: the file ends at byte %llu inside a record or packet (ignored; the complete "
                "ones are read)\n",
                u(w.truncated_at));
  else
    std::printf("truncated:     no\n");
  for (const auto& m : info.warnings.messages) std::printf("  warning: %s\n", m.c_str());
  return 0;
}
}  // namespace

void registerInfo(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  auto* cmd = app.add_subcommand(
      "info", "What an event recording holds: format, sensor size, counts, ON share, duration, rates, warnings");
  cmd->add_option("input", args->path, "events file (events.txt, .aedat, .aedat2, .aedat31, .aedat4, ROS .bag, HDF5 .h5/.hdf5) or RPG/UZH-FPV directory; a bag lists its topics with types, counts and rates")
      ->required();
  cmd->add_option("--width", args->width, "sensor width [px]; overrides the file's (0 = from the file, or unknown)");
  cmd->add_option("--height", args->height, "sensor height [px]; overrides the file's (0 = from the file, or unknown)");
  cmd->add_option("--imu-columns", args->imu_columns, "IMU text column order without a header: auto | rpg | gyro_first")
      ->capture_default_str();
  cmd->add_option("--time-scale", args->time_scale, "text timestamps times this = seconds (1e-6 for us)")
      ->capture_default_str();
  cmd->add_option("--topic-events", args->topic_events, "ROS bag events topic (default: the dvs_msgs/EventArray topic)");
  cmd->add_option("--topic-imu", args->topic_imu, "ROS bag IMU topic (default: the sensor_msgs/Imu topic)");
  cmd->add_option("--topic-pose", args->topic_pose,
                  "ROS bag pose topic (default: the geometry_msgs/PoseStamped or nav_msgs/Odometry topic)");
  cmd->add_option("--backwards", args->backwards,
                  "timestamps more than input.backwards_tolerance before the latest earlier one: error | drop | sort")
      ->check(CLI::IsMember({"error", "drop", "sort"}))
      ->capture_default_str();
  cmd->add_option("--max-time-jump", args->max_time_jump,
                  "largest plausible step between events [s]: one event beyond it is an outlier (dropped), "
                  "a confirmed one a gap (kept)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--strict", args->strict, "treat warnings (backwards timestamps, pixels outside) as errors");
  cmd->callback([args]() {
    const int rc = runInfo(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace celc::app
