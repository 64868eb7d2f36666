#include "run_common.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <fmt/format.h>
#include <iostream>
#include <sstream>

#include "celc/core/text.hpp"
#include "celc/core/yaml.hpp"
#include "celc/io/event_reader.hpp"

namespace celc::app {

void addRunOptions(CLI::App* cmd, RunOverrides& o) {
  cmd->add_option("-c,--config", o.config, "YAML configuration (see config/run.yaml)")
      ->check(CLI::ExistingFile);
  // Help of the options that stand for a configuration key: from the schema.
  RunConfig defaults;
  const Describe schema = [&](FieldVisitor& v) { describe(v, defaults); };
  cmd->add_option("--window-events", o.window_events,
                  "windows of a fixed event count (windows.policy events): " + fieldHelp(schema, "windows.events"));
  cmd->add_option("--window-seconds", o.window_seconds,
                  "windows of a fixed duration (windows.policy seconds): " + fieldHelp(schema, "windows.seconds"));
  cmd->add_option("--methods", o.methods,
                  "comma-separated celc,celc_opt,celc_ml,ce3lc,npt,celc_acc (or all): " + fieldHelp(schema, "methods"));
  cmd->add_option("--omega", o.omega,
                  "assume this constant angular velocity wx,wy,wz [rad/s, camera frame] instead of "
                  "the gyroscope (recordings without IMU)");
  cmd->add_option("--motion-model", o.motion_model, fieldHelp(schema, "motion.model"));
  cmd->add_option("--topic-events", o.topic_events, fieldHelp(schema, "input.topic_events"));
  cmd->add_option("--topic-imu", o.topic_imu, fieldHelp(schema, "input.topic_imu"));
  cmd->add_option("--topic-pose", o.topic_pose, fieldHelp(schema, "input.topic_pose"));
  cmd->add_option("--threads", o.threads,
                  "windows solved at once (0 = all cores, at most 1024); with 1, a window is clustered, redrawn "
                  "and solved on cluster.threads threads (--set cluster.threads=1 for one thread in all)")
      ->capture_default_str();
  cmd->add_option("--set", o.sets,
                  "override any configuration key, e.g. --set cluster.smoothness_deg=15 "
                  "(repeatable; YAML values; `celc config --keys` lists every key)");
  cmd->add_option("--shard", o.shard, "K/N: process only windows with index % N == K-1");
  cmd->add_flag("--force", o.force,
                "replace results already in the output folder (with --resume: replace them only when "
                "the stored configuration differs)");
  cmd->add_flag("--resume", o.resume,
                "continue a run after its last finished window; refused when OUTDIR/config.yaml differs "
                "from this configuration");
  cmd->add_flag("--no-plots", o.no_plots,
                "skip the plots OUTDIR/velocity.png and error.png (scripts/plot_run.py, python3-matplotlib)");
  cmd->add_flag("-q,--quiet", o.quiet, "only warnings and errors on stderr");
  cmd->add_flag("-v,--verbose", o.verbose, "debug logging");
}

void applySets(const std::vector<std::string>& sets, RunConfig& c) {
  applyRunSettings(sets, c);
}

namespace {

// A whole number of events > 0, or an error naming the option.
std::size_t parseWindowEvents(const std::string& text) {
  std::size_t used = 0;
  long long n = 0;
  try {
    n = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || n <= 0)
    throw std::runtime_error("--window-events '" + text + "': expected a positive whole number of events");
  return static_cast<std::size_t>(n);
}

// A finite duration > 0 [s], or an error naming the option.
double parseWindowSeconds(const std::string& text) {
  std::size_t used = 0;
  double s = 0.0;
  try {
    s = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(s) || !(s > 0.0))
    throw std::runtime_error("--window-seconds '" + text + "': expected a positive, finite duration [s]");
  return s;
}

}  // namespace

void checkThreads(int threads) {
  if (threads < 0 || threads > kMaxThreads)
    throw std::runtime_error("--threads " + std::to_string(threads) + ": expected 0 (all cores) to " +
                             std::to_string(kMaxThreads));
}

RunConfig buildRunConfig(const RunOverrides& o) {
  checkThreads(o.threads);
  if (!o.window_events.empty() && !o.window_seconds.empty())
    throw std::runtime_error("--window-events, --window-seconds: give one of them, not both");
  RunConfig c = o.config.empty() ? RunConfig{} : loadRunConfig(o.config);
  if (!o.window_events.empty()) {
    c.window_policy = WindowPolicy::Events;
    c.windows.events_per_window = parseWindowEvents(o.window_events);
    c.windows.seconds_per_window = 0.0;
  }
  if (!o.window_seconds.empty()) {
    const double s = parseWindowSeconds(o.window_seconds);
    const double per_second = 1.0 / ((1.0 - c.windows.overlap) * s);
    if (!(per_second <= c.windows.max_windows_per_second))
      throw std::runtime_error(fmt::format(
          "--window-seconds {}: {:.3g} windows per second of data, more than windows.max_windows_per_second = {:g}",
          o.window_seconds, per_second, c.windows.max_windows_per_second));
    c.window_policy = WindowPolicy::Seconds;
    c.windows.seconds_per_window = s;
    c.windows.events_per_window = 0;
  }
  if (!o.methods.empty()) c.methods = parseMethodList(o.methods);
  if (!o.motion_model.empty()) c.motion = parseMotionModelKind(o.motion_model);
  if (!o.omega.empty()) {
    std::vector<double> w;
    for (const std::string& item : splitList(o.omega, ',')) {
      try {
        w.push_back(std::stod(item));
      } catch (const std::exception&) {
        throw std::runtime_error("--omega '" + o.omega + "': expected wx,wy,wz [rad/s]");
      }
    }
    if (w.size() != 3) throw std::runtime_error("--omega '" + o.omega + "': expected wx,wy,wz [rad/s]");
    c.omega_source = OmegaSource::Fixed;
    c.fixed_omega = Vec3(w[0], w[1], w[2]);
  }
  if (!o.topic_events.empty()) c.reader.topic_events = o.topic_events;
  if (!o.topic_imu.empty()) c.reader.topic_imu = o.topic_imu;
  if (!o.topic_pose.empty()) c.reader.topic_pose = o.topic_pose;
  applySets(o.sets, c);
  // Windows run in parallel: keep each window's clustering on one thread.
  if (o.threads != 1) c.cluster.threads = 1;
  if (const std::string err = c.validate(); !err.empty()) throw std::runtime_error("configuration: " + err);
  return c;
}

OutputMode outputMode(const RunOverrides& o) {
  if (o.force && o.resume) return OutputMode::ResumeOrReplace;
  return o.resume ? OutputMode::Resume : (o.force ? OutputMode::Force : OutputMode::Create);
}

void printSummary(const std::string& title, const SequenceOutcome& out) {
  auto f = [](double x) { return std::isfinite(x) ? fmt::format("{:.4f}", x) : std::string("-"); };
  std::cout << "\n" << title << "\n\n"
            << "| method | windows | ok | with gt | mean eps (unit-vector distance) | median eps (unit-vector distance) | mean phi [rad] | median phi [rad] | consistency R |\n"
            << "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& m : out.summaries)
    std::cout << "| " << m.method << " | " << m.windows << " | " << m.ok << " | " << m.with_metrics
              << " | " << f(m.eps_mean) << " | " << f(m.eps_median) << " | " << f(m.phi_mean) << " | "
              << f(m.phi_median) << " | " << f(m.resultant_length) << " |\n";
  for (const auto& n : out.notes) std::cout << "- " << n << "\n";
  std::cout << std::flush;
}

}  // namespace celc::app
