#include "celc/pipeline/sequence_runner.hpp"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>

#include "celc/geometry/undistort.hpp"
#include "celc/io/calibration.hpp"
#include "celc/io/text_io.hpp"

namespace fs = std::filesystem;

namespace celc {

namespace {
using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
std::string firstExisting(const fs::path& dir, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (fs::exists(dir / n)) return (dir / n).string();
  return {};
}
}  // namespace

struct SequenceRunner::Impl {
  RunConfig config;
  RunInputs inputs;
  io::Calibration calib;
  std::unique_ptr<io::EventReader> reader;
  std::unique_ptr<UndistortLut> lut;
  io::GyroTrack gyro;
  std::unique_ptr<eval::GtVelocityEstimator> gt;
  std::size_t n_imu = 0, n_poses = 0;
};

SequenceRunner::SequenceRunner(const RunInputs& in, const RunConfig& config)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = config;
  m.inputs = in;
  if (const std::string err = config.validate(); !err.empty())
    throw std::runtime_error("configuration: " + err);
  if (!fs::exists(in.events)) throw std::runtime_error(in.events + ": no such file or directory");
  const bool is_dir = fs::is_directory(in.events);
  const fs::path dir = is_dir ? fs::path(in.events) : fs::path(in.events).parent_path();
  if (m.inputs.calib.empty() && is_dir)
    m.inputs.calib = firstExisting(dir, {"calib.yaml", "calib.yml", "calib.txt"});
  if (m.inputs.groundtruth.empty() && is_dir)
    m.inputs.groundtruth = firstExisting(dir, {"groundtruth.txt"});
  if (m.inputs.calib.empty())
    throw std::runtime_error(in.events + ": no calibration (give --calib, or put calib.yaml / calib.txt in the sequence directory)");

  m.reader = io::openEventSource(in.events, m.config.reader);
  const int w = m.reader->width() > 0 ? m.reader->width() : 240;
  const int h = m.reader->height() > 0 ? m.reader->height() : 180;
  m.calib = io::loadCalibration(m.inputs.calib, w, h);
  m.lut = std::make_unique<UndistortLut>(m.calib.camera);

  if (m.config.omega_source == OmegaSource::Gyro) {
    std::vector<ImuSample> imu = m.inputs.imu.empty() ? m.reader->readImu()
                                                      : io::readImuText(m.inputs.imu, m.config.reader);
    m.n_imu = imu.size();
    if (!imu.empty()) m.gyro = io::GyroTrack(imu, m.calib.R_cam_imu, m.calib.time_offset, m.config.gyro);
  }
  if (!m.inputs.groundtruth.empty()) {
    auto poses = io::readPosesText(m.inputs.groundtruth, m.config.reader);
    m.n_poses = poses.size();
    if (!poses.empty())
      m.gt = std::make_unique<eval::GtVelocityEstimator>(std::move(poses), m.calib.T_body_cam,
                                                         m.config.groundtruth);
  }
}

SequenceRunner::~SequenceRunner() = default;

bool SequenceRunner::hasGroundTruth() const { return impl_->gt != nullptr; }
bool SequenceRunner::hasImu() const { return !impl_->gyro.empty(); }

std::vector<std::string> SequenceRunner::describe() const {
  const Impl& m = *impl_;
  std::vector<std::string> d;
  d.push_back("events: " + m.reader->path() + " (" + io::toString(m.reader->format()) + ")");
  d.push_back("calibration: " + m.inputs.calib + " (" + std::to_string(m.calib.camera.width) + "x" +
              std::to_string(m.calib.camera.height) + ", " + toString(m.calib.camera.distortion) + ")");
  if (m.config.omega_source == OmegaSource::Fixed)
    d.push_back("angular velocity: fixed by the configuration (motion.fixed_omega)");
  else
    d.push_back("gyroscope: " + std::to_string(m.n_imu) + " samples");
  d.push_back(m.gt ? "ground truth: " + m.inputs.groundtruth + " (" + std::to_string(m.n_poses) + " poses)"
                   : std::string("ground truth: none (no metrics)"));
  return d;
}

WindowRecord SequenceRunner::processWindow(std::uint64_t index, double t0, double t1,
                                           const std::vector<Event>& events) const {
  const Impl& m = *impl_;
  const RunConfig& cfg = m.config;
  WindowRecord rec;
  // Every method gets a row; an early exit leaves them without an estimate.
  for (Method method : cfg.methods) {
    MethodRow row;
    row.method = method;
    rec.rows.push_back(row);
  }
  rec.index = index;
  rec.t0 = t0;
  rec.t1 = t1;
  rec.n_events = events.size();

  // Ground truth first: it does not depend on the estimate.
  auto start = Clock::now();
  if (m.gt) {
    const eval::GtVelocity g = m.gt->window(t0, t1);
    if (g.ok() && g.v_cam.norm() > 1e-9) {
      rec.has_gt = true;
      rec.gt_speed = g.v_cam.norm();
      rec.gt = g.v_cam / rec.gt_speed;
    }
  }
  rec.times.groundtruth = secondsSince(start);

  // The angular velocity for the window.
  MotionModel motion = MotionModel::constantTwist(cfg.fixed_omega, t0);
  if (cfg.omega_source == OmegaSource::Gyro) {
    if (m.gyro.empty()) {
      rec.window_status = "no_gyro";
      return rec;
    }
    const io::GyroWindow gw = m.gyro.window(t0, t1);
    if (!gw.ok()) {
      rec.window_status = io::toString(gw.status);
      return rec;
    }
    motion = cfg.motion == MotionModelKind::GyroIntegrated ? gw.motionModel(t0)
                                                           : MotionModel::constantTwist(gw.mean_omega, t0);
  }

  // Clustering in pixel space-time.
  start = Clock::now();
  const ClusterResult clusters = clusterEvents(events, cfg.cluster);
  rec.times.cluster = secondsSince(start);
  if (clusters.status != ClusterStatus::Ok) {
    rec.window_status = toString(clusters.status);
    return rec;
  }

  // Undistorted bearings and boundary lines per cluster.
  start = Clock::now();
  const UndistortLut& lut = *m.lut;
  const CameraModel& cam = m.calib.camera;
  auto bearing = [&](const Vec2& p) {
    Vec3 b;
    const double rx = std::round(p.x()), ry = std::round(p.y());
    if (rx == p.x() && ry == p.y() && lut.bearing(static_cast<int>(rx), static_cast<int>(ry), b)) return b;
    return cam.bearing(p);  // sub-pixel or outside the table
  };
  ObservationReport report;
  const WindowObservations obs =
      toObservations(events, clusters, bearing, cam.focal(), cfg.observations, &report);
  rec.n_clusters = static_cast<int>(obs.clusters.size());
  rec.times.lines = secondsSince(start);

  start = Clock::now();
  SolverOptions so = cfg.solver;
  so.linear.seed = cfg.seed + index;
  so.refine.seed = cfg.seed + index;
  const std::vector<SolverResult> results = solveMethods(obs, motion, cfg.methods, so);
  rec.times.solve = secondsSince(start);
  for (size_t i = 0; i < cfg.methods.size(); ++i) {
    MethodRow& row = rec.rows[i];
    row.result = results[i];
    if (row.result.ok() && rec.has_gt) {
      row.has_metrics = true;
      row.eps = (rec.gt - row.result.v).norm();
      row.phi = angleBetween(rec.gt, row.result.v);
    }
  }
  return rec;
}

RunStats SequenceRunner::run(int threads, const WindowFilter& filter,
                             const std::function<void(const WindowRecord&)>& sink,
                             const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  Impl& m = *impl_;
  RunStats stats;
  const auto start = Clock::now();
  const int n_workers = std::max(1, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()));

  struct Job {
    std::uint64_t index;
    double t0, t1;
    std::vector<Event> events;
  };
  std::mutex mu;
  std::condition_variable cv_jobs, cv_done;
  std::deque<Job> jobs;
  std::map<std::uint64_t, WindowRecord> done;  // finished, waiting for their turn
  bool no_more = false;
  std::exception_ptr error;
  const std::size_t max_in_flight = static_cast<std::size_t>(n_workers) + 2;  // memory bound

  auto worker = [&]() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mu);
        cv_jobs.wait(lock, [&] { return !jobs.empty() || no_more; });
        if (jobs.empty()) return;
        job = std::move(jobs.front());
        jobs.pop_front();
      }
      WindowRecord rec;
      try {
        rec = processWindow(job.index, job.t0, job.t1, job.events);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        if (!error) error = std::current_exception();
        rec.index = job.index;
        rec.window_status = "error";
      }
      {
        std::lock_guard<std::mutex> lock(mu);
        done.emplace(job.index, std::move(rec));
      }
      cv_done.notify_all();
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < n_workers; ++i) pool.emplace_back(worker);

  // Hands finished windows to the sink in order; returns how many are in flight.
  std::vector<std::uint64_t> order;  // indices submitted, in order
  std::size_t next_out = 0;
  auto drain = [&](bool wait_all) {
    for (;;) {
      WindowRecord rec;
      {
        std::unique_lock<std::mutex> lock(mu);
        const std::size_t in_flight = order.size() - next_out;
        if (in_flight == 0) return;
        const bool must_wait = wait_all || in_flight >= max_in_flight;
        const std::uint64_t want = order[next_out];
        if (!done.count(want)) {
          if (!must_wait) return;
          cv_done.wait(lock, [&] { return done.count(want) > 0; });
        }
        rec = std::move(done[want]);
        done.erase(want);
        ++next_out;
      }
      stats.windows_processed++;
      stats.events_processed += rec.n_events;
      stats.stage_seconds.cluster += rec.times.cluster;
      stats.stage_seconds.lines += rec.times.lines;
      stats.stage_seconds.solve += rec.times.solve;
      stats.stage_seconds.groundtruth += rec.times.groundtruth;
      sink(rec);
      if (progress) progress(stats.windows_processed, stats.events_processed);
    }
  };

  try {
    io::WindowSource source(*m.reader, m.config.windows);
    io::EventWindow window;
    for (;;) {
      const auto t_read = Clock::now();
      const bool more = source.next(window);
      stats.seconds_reading += secondsSince(t_read);
      if (!more) break;
      stats.windows_read++;
      stats.events_read += window.events.size();
      const auto idx = static_cast<std::int64_t>(window.index);
      const bool wanted = idx > filter.after && filter.shard_count > 0 &&
                          idx % filter.shard_count == filter.shard_index;
      if (!wanted) continue;
      {
        std::lock_guard<std::mutex> lock(mu);
        jobs.push_back(Job{window.index, window.t0, window.t1, std::move(window.events)});
        order.push_back(window.index);
      }
      window.events = {};
      cv_jobs.notify_one();
      drain(false);
      {
        std::lock_guard<std::mutex> lock(mu);
        if (error) break;
      }
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mu);
    if (!error) error = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(mu);
    no_more = true;
  }
  cv_jobs.notify_all();
  if (!error) drain(true);
  for (auto& t : pool) t.join();
  stats.reader_warnings = m.reader->warnings().total();
  stats.seconds_total = secondsSince(start);
  if (error) std::rethrow_exception(error);
  return stats;
}

}  // namespace celc
