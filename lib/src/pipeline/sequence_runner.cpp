#include "celc/pipeline/sequence_runner.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "celc/cluster/derotate.hpp"
#include "celc/cluster/line_split.hpp"
#include "celc/cluster/motion_reassign.hpp"
#include "celc/core/parallel.hpp"
#include "celc/eval/metrics.hpp"
#include "celc/geometry/undistort.hpp"
#include "celc/io/calibration.hpp"
#include "celc/io/sequence_layout.hpp"
#include "celc/io/text_io.hpp"
#include "celc/io/truth_labels.hpp"
#include "celc/pipeline/accelerometer.hpp"
#include "celc/pipeline/imu_still.hpp"

namespace fs = std::filesystem;

namespace celc {

namespace {
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

struct SequenceRunner::Impl {
  RunConfig config;
  RunInputs inputs;
  Calibration calib;
  bool size_assumed = false;  ///< the image size is calib.txt's default, stated by no file
  std::unique_ptr<EventReader> reader;
  std::unique_ptr<UndistortLut> lut;
  GyroTrack gyro;
  Vec3 gyro_bias = Vec3::Zero();  ///< subtracted from every gyro sample [rad/s], IMU frame
  std::string gyro_note;          ///< where gyro_bias comes from, when it is not zero
  std::vector<std::string> notes; ///< the still-second check, when no bias came of it
  std::unique_ptr<GtVelocityEstimator> gt;
  std::size_t n_imu = 0, n_poses = 0;
  std::optional<WindowDumpContext> dump;  ///< dumpWindows()
  std::optional<TruthLabels> truth;       ///< RunInputs::truth_labels, when there are any
  AccelerometerTrack accelerometer;       ///< empty without accelerometer or still span
  std::string accelerometer_note;         ///< how the accelerometer is used, or why not

  /// The accelerometer track from the IMU (gyro bias removed) and its still
  /// span, or the note why there is none.
  void setUpAccelerometer(const std::vector<ImuSample>& imu, const StillSpan& still) {
    if (!still.has_accel) {
      accelerometer_note = "accelerometer: none (every sample 0)";
    } else if (!still.found) {
      accelerometer_note = "accelerometer: not used, no still second for gravity (" + still.refused + ")";
    } else {
      accelerometer = AccelerometerTrack(imu, calib.R_cam_imu, calib.time_offset, still, config.accelerometer,
                                         config.gyro.max_gap);
      const Vec3& g = accelerometer.gravity();
      accelerometer_note = fmt::format(
          "accelerometer: gravity {:.3f},{:.3f},{:.3f} m/s^2 (camera frame) from the still second [{:.3f}, {:.3f}] "
          "s; celc_acc checks its acceleration against it (motion.use_accelerometer)",
          g.x(), g.y(), g.z(), still.t0, still.t1);
    }
    spdlog::info("{}", accelerometer_note);
  }

  /// The window's clusters against the true edges (`labels`: the clusters
  /// the solvers see, fragments of one edge joined), and celc_ml on the true
  /// clusters of the same events with the same lines code, motion and seed.
  void measureAgainstTruth(WindowRecord& rec, const std::vector<Event>& events, const std::vector<int>& labels,
                           const MotionModel& motion) const {
    const auto start = Clock::now();
    const std::vector<int> edges = truth->lookup(events);
    rec.has_truth = true;
    rec.quality = measureClusterQuality(labels, edges);
    const ClusterResult true_clusters = clustersFromLabels(events, edges);
    if (true_clusters.status != ClusterStatus::Ok) return;
    auto to_bearing = [&](const Vec2& p) { return bearing(p); };
    const WindowObservations obs = toObservations(events, true_clusters, to_bearing, calib.camera.focal(),
                                                  config.observations, &motion, nullptr);
    const SampleSeeds seeds{config.seed + rec.index, config.seed + rec.index};
    const std::vector<SolverResult> oracle = solveMethods(obs, motion, {Method::CelcMl}, config.solver, seeds);
    if (rec.has_gt && oracle.front().ok()) rec.oracle_phi = directionAngle(rec.gt, oracle.front().v);
    rec.times.truth = secondsSince(start);
  }

  /// The solver options of the witness's solves while the clusters are
  /// redrawn: the run's, without sigma_deg (only v is used).
  SolverOptions witnessOptions() const {
    SolverOptions options = config.solver;
    options.uncertainty.enabled = false;
    return options;
  }

  /// The method whose answer redraws the clusters (cluster.motion_reassign_px):
  /// the first of celc_ml, celc_opt, celc among the run's methods; none when
  /// the redraw is off or the run has none of them.
  std::optional<Method> redrawWitness(const ClusterOptions& cluster_options) const {
    if (!(cluster_options.motion_reassign_px > 0.0)) return std::nullopt;
    for (Method preferred : {Method::CelcMl, Method::CelcOpt, Method::Celc})
      if (std::find(config.methods.begin(), config.methods.end(), preferred) != config.methods.end()) return preferred;
    return std::nullopt;
  }

  /// The window's clusters redrawn under the witness's answer `first`
  /// (cluster/motion_reassign.hpp), with their observations. Kept, replacing
  /// `first` (by the witness's answer on them), `labels` (the clusters before
  /// fragments join; when given), `report`, `obs`, `members` (toObservations')
  /// and `solves` (the witness's shared estimates on them), when
  /// the witness answers on them and the window's cost per event under that
  /// answer and its clusters (motionCost) is below the first answer's with
  /// the first clusters. Returns whether it was kept.
  /// `drawn_from` holds the clusters' labels (clustersFromLabels') a kept
  /// redraw built `obs` from, empty before one is kept: a redraw that gives
  /// them again would give the same observations, answer and cost, so it is
  /// not kept, without solving again. `lines`: the kept redraw's clusters'
  /// lines under its answer, which the next redraw starts from.
  /// While the clusters are redrawn and their observations built and
  /// solved, `obs` holds no events (dropObservationEvents): a redraw not
  /// kept restores them from `members`, the very values, so that one set of
  /// a window's events is held as observations at a time.
  bool redrawUnderMotion(const std::vector<Event>& events, const MotionModel& motion, const SampleSeeds& seeds,
                         const ClusterOptions& cluster_options, std::uint64_t index, Method witness,
                         SolverResult& first, std::vector<int>* labels, ObservationReport& report,
                         WindowObservations& obs, std::vector<std::vector<int>>& members, SharedSolves& solves,
                         std::vector<int>& drawn_from, MotionLines& lines) const {
    auto to_bearing = [&](const Vec2& p) { return bearing(p); };
    dropObservationEvents(obs);
    auto notKept = [&] {
      restoreObservationEvents(obs, events, members, to_bearing);
      return false;
    };
    std::vector<int> redrawn = report.event_clusters;
    const MotionReassignReport redraw = reassignToMotionLines(events, redrawn, to_bearing, calib.camera.focal(),
                                                              motion, first.v, cluster_options, &lines);
    ClusterResult clusters = clustersFromLabels(events, redrawn);
    std::vector<int>().swap(redrawn);  // `clusters` holds them, renumbered
    if (clusters.labels == drawn_from) {
      spdlog::debug("window {}: clusters under the motion: unchanged, not kept", index);
      return notKept();
    }
    if (clusters.status != ClusterStatus::Ok) return notKept();
    ObservationReport redrawn_report;
    std::vector<std::vector<int>> redrawn_members;
    WindowObservations redrawn_obs =
        toObservations(events, clusters, to_bearing, calib.camera.focal(), config.observations, &motion,
                       &redrawn_report, &redrawn_members, cluster_options.threads);
    SharedSolves redrawn_solves;
    const SolverResult after =
        solveMethods(redrawn_obs, motion, {witness}, witnessOptions(), seeds, redrawn_solves).front();
    // The window's cost per event (every event: the same set both times)
    // under each answer with its clusters.
    const double cost_before = redraw.cost;
    MotionLines lines_after;
    if (after.ok())
      lines_after = fitMotionLines(events, redrawn_report.event_clusters, to_bearing, calib.camera.focal(), motion,
                                   after.v, cluster_options);
    const double cost_after = lines_after.cost();
    const bool keep = cost_after < cost_before;
    spdlog::debug("window {}: clusters under the motion: {} joined, {} moved, {} ambiguous, {} removed, "
                  "{} of {} lines unexplained; {}: {:.2f} deg from the first answer, cost per event {:.4f} -> {:.4f}: "
                  "{}",
                  index, redraw.n_joined, redraw.n_moved, redraw.n_ambiguous, redraw.n_removed,
                  redraw.n_unexplained, redraw.n_lines, toString(witness),
                  angleBetweenSignAgnostic(first.v, after.v) * 180.0 / M_PI, cost_before, cost_after,
                  keep ? "kept" : "not kept");
    if (!keep) {
      redrawn_obs = WindowObservations();
      return notKept();
    }
    first = after;
    if (labels) *labels = clusters.labels;
    drawn_from = std::move(clusters.labels);
    lines = std::move(lines_after);
    report = std::move(redrawn_report);
    obs = std::move(redrawn_obs);
    members = std::move(redrawn_members);
    solves = std::move(redrawn_solves);
    return true;
  }

  /// Unit-plane bearing (x, y, 1) of a pixel: the undistortion table at whole
  /// pixels, the camera model elsewhere.
  /// Every pass over a window's events asks for it (the cut, the lines, each
  /// redraw), so the whole-pixel test is two conversions, not calls of round.
  Vec3 bearing(const Vec2& p) const {
    Vec3 b;
    int x, y;
    if (wholePixel(p.x(), x) && wholePixel(p.y(), y) && lut->bearing(x, y, b)) return b;
    return calib.camera.bearing(p);  // sub-pixel or outside the table
  }
  /// Whether v is a whole number in int's range, `out` then v.
  static bool wholePixel(double v, int& out) {
    if (!(v > -2147483648.0 && v < 2147483647.0)) return false;
    out = static_cast<int>(v);
    return static_cast<double>(out) == v;
  }
  /// The window's motion model, or false with the reason (no_gyro, a gyro window status).
  bool motionFor(double t0, double t1, MotionModel& motion, Vec3& omega, std::string& status) const {
    motion = MotionModel::constantTwist(config.fixed_omega, t0);
    omega = config.fixed_omega;
    if (config.omega_source != OmegaSource::Gyro) return true;
    if (gyro.empty()) {
      status = "no_gyro";
      return false;
    }
    const GyroWindow gw = gyro.window(t0, t1);
    if (!gw.ok()) {
      status = toString(gw.status);
      return false;
    }
    motion = config.motion == MotionModelKind::GyroIntegrated ? gw.motionModel(t0)
                                                              : MotionModel::constantTwist(gw.mean_omega, t0);
    omega = gw.mean_omega;
    return true;
  }
  /// How far the camera turns over [t0, t1] [rad]: |mean rate| (t1 - t0), the
  /// gyroscope's mean or motion.fixed_omega; NaN where the gyroscope does not
  /// cover the span.
  double turnAngle(double t0, double t1) const {
    MotionModel motion = MotionModel::constantTwist(Vec3::Zero(), t0);
    Vec3 omega;
    std::string status;
    if (!motionFor(t0, t1, motion, omega, status)) return NAN;
    return omega.norm() * (t1 - t0);
  }
  /// D of a growing parallax window (window_policy.hpp) [px], measured on at
  /// most parallax.probe_events of its events (every k-th); NaN when it cannot
  /// be measured (no motion model, clustering failed, too few lines).
  /// Every k-th event is k times sparser in (x, y, c t), and the clustering's
  /// density checks can then find no cluster: a probe without a D is repeated
  /// with a 4 times denser subset, down to every event.
  double probeTranslation(double t0, double t1, const std::vector<Event>& events, int cluster_threads) const {
    MotionModel motion = MotionModel::constantTwist(Vec3::Zero(), t0);
    Vec3 omega;
    std::string status;
    if (!motionFor(t0, t1, motion, omega, status)) return NAN;
    const std::size_t budget = config.parallax.probeBudget(t1 - t0);
    std::size_t keep_every = std::max<std::size_t>(1, (events.size() + budget - 1) / budget);
    // A k times sparser subset needs longer time neighbourhoods: the probe
    // clusters at c = the median normal speed (factor at most 1, the
    // default); D is a median over clusters and needs no purity.
    ClusterOptions cluster = config.cluster;
    cluster.c_speed_factor = std::min(1.0, cluster.c_speed_factor);
    if (cluster_threads > 0) cluster.threads = cluster_threads;
    for (;;) {
      std::vector<Event> probe;
      probe.reserve(events.size() / keep_every + 1);
      for (std::size_t i = 0; i < events.size(); i += keep_every) probe.push_back(events[i]);
      const ClusterResult clusters = clusterEvents(probe, cluster);
      double d = NAN;
      if (clusters.status == ClusterStatus::Ok) {
        const WindowObservations obs = toObservations(
            probe, clusters, [&](const Vec2& p) { return bearing(p); }, calib.camera.focal(),
            config.observations, &motion, nullptr);
        d = lineTranslationPx(obs, motion, t0, t1);
      }
      if (std::isfinite(d) || keep_every == 1) return d;
      keep_every = std::max<std::size_t>(1, keep_every / 4);
    }
  }
};

SequenceRunner::SequenceRunner(const RunInputs& in, const RunConfig& config)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = config;
  m.inputs = in;
  if (const std::string err = config.validate(); !err.empty())
    throw std::runtime_error("configuration: " + err);
  if (const std::string why = clusterMethodProblem(config.cluster.method); !why.empty())
    throw std::runtime_error("configuration: cluster.method: " + why);
  if (!fs::exists(in.events)) throw std::runtime_error(in.events + ": no such file or directory");
  if (fs::is_directory(in.events)) {  // a sequence directory: what the inputs do not name
    const SequenceLayout layout = resolveSequenceLayout(in.events);
    if (m.inputs.calib.empty()) m.inputs.calib = layout.calib;
    if (m.inputs.groundtruth.empty()) m.inputs.groundtruth = layout.groundtruth;
    const std::string labels = sequenceFilePath(in.events, sequence_file::kLabels);
    if (m.inputs.truth_labels.empty() && fs::is_regular_file(labels)) m.inputs.truth_labels = labels;
  }
  if (m.inputs.calib.empty())
    throw std::runtime_error(in.events + ": no calibration (give --calib, or put " +
                             sequence_file::kCalibYaml + " / " + sequence_file::kCalibText +
                             " in the sequence directory)");

  m.reader = openEventSource(in.events, m.config.reader);
  const int w = m.reader->width() > 0 ? m.reader->width() : 240;
  const int h = m.reader->height() > 0 ? m.reader->height() : 180;
  m.calib = loadCalibration(m.inputs.calib, w, h);
  // A recording that states no sensor size is read against the calibration's
  // size: pixels outside it are counted and dropped (an error beyond
  // input.max_outside_share, naming input.width / input.height), as for a
  // file that states its size, instead of used silently. A calib.txt states
  // no size either: its camera is the 240x180 DAVIS240C's, and the summary
  // says that size is assumed.
  const std::string calib_ext = fs::path(m.inputs.calib).extension().string();
  if (m.reader->width() <= 0 && m.config.reader.width <= 0 && m.config.reader.height <= 0 &&
      m.calib.camera.width > 0 && m.calib.camera.height > 0) {
    m.size_assumed = calib_ext != ".yaml" && calib_ext != ".yml" && !isContainerFile(m.inputs.calib);
    m.config.reader.width = m.calib.camera.width;
    m.config.reader.height = m.calib.camera.height;
    m.reader = openEventSource(in.events, m.config.reader);
    if (m.size_assumed)
      spdlog::warn("{}: neither it nor {} states an image size: the events are read as from a {}x{} sensor "
                   "(pixels outside are dropped and counted, an error beyond input.max_outside_share); set "
                   "input.width / input.height for another camera",
                   m.inputs.calib, in.events, m.calib.camera.width, m.calib.camera.height);
  }
  // A calibration of another sensor maps every pixel to a wrong bearing.
  if (m.reader->width() > 0 && m.reader->height() > 0 &&
      (m.calib.camera.width != m.reader->width() || m.calib.camera.height != m.reader->height()))
    throw std::runtime_error(m.inputs.calib + ": calibration of a " + std::to_string(m.calib.camera.width) + "x" +
                             std::to_string(m.calib.camera.height) + " image, but " + in.events + " is from a " +
                             std::to_string(m.reader->width()) + "x" + std::to_string(m.reader->height()) +
                             " sensor");
  m.lut = std::make_unique<UndistortLut>(m.calib.camera);

  if (m.config.omega_source == OmegaSource::Gyro) {
    std::vector<ImuSample> imu = m.inputs.imu.empty() ? m.reader->readImu()
                                                      : readImuText(m.inputs.imu, m.config.reader);
    m.n_imu = imu.size();
    if (imu.empty())
      throw std::runtime_error((m.inputs.imu.empty() ? in.events : m.inputs.imu) +
                               ": no IMU samples; give --imu FILE, or --omega wx,wy,wz [rad/s] "
                               "(motion.omega_source: fixed) for a recording without IMU");
    // The constant gyro bias (IMU frame) comes off every sample here, before
    // the track rotates the rates into the camera frame.
    m.gyro_bias = m.config.gyro_bias;
    if (!m.gyro_bias.isZero(0.0)) m.gyro_note = "motion.gyro_bias";
    const StillBias from_still = m.config.gyro_bias_from_still;
    const bool bias_from_still =
        from_still == StillBias::On || (from_still == StillBias::Auto && m.gyro_bias.isZero(0.0));
    const StillSpan still = bias_from_still || m.config.accelerometer.use ? findFirstStill(imu) : StillSpan{};
    if (bias_from_still) {
      const std::string imu_path = m.inputs.imu.empty() ? in.events : m.inputs.imu;
      if (!still.warning.empty()) {
        spdlog::warn("{}: {}", imu_path, still.warning);
        m.notes.push_back("gyro at rest: " + still.warning);
      }
      const std::string span = still.found ? fmt::format("[{:.3f}, {:.3f}] s", still.t0, still.t1) : "";
      if (from_still == StillBias::On && !still.found)
        throw std::runtime_error(imu_path + ": motion.gyro_bias_from_still: the IMU has no still second (" +
                                 std::to_string(imu.size()) + " samples; " + still.refused +
                                 "); set motion.gyro_bias instead");
      if (from_still == StillBias::On) {
        m.gyro_bias = still.gyro_mean;
        m.gyro_note = "the mean over the first still second " + span + " (motion.gyro_bias_from_still: true)";
      } else if (still.found && still.significant(kStillBiasZ, kStillBiasMinRate)) {
        m.gyro_bias = still.gyro_mean;
        m.gyro_note = fmt::format("the mean over the first still second {} (gyro std {:.4f},{:.4f},{:.4f} rad/s, "
                                  "{} samples; motion.gyro_bias_from_still: auto, false keeps the raw rates)",
                                  span, still.gyro_std.x(), still.gyro_std.y(), still.gyro_std.z(), still.samples);
      } else if (still.found) {
        m.notes.push_back(fmt::format(
            "gyro bias: none subtracted; the first still second {} has a mean rate of {:.4f} rad/s, within the "
            "noise (motion.gyro_bias_from_still: auto subtracts {} standard errors and {} rad/s or more)",
            span, still.gyro_mean.norm(), kStillBiasZ, kStillBiasMinRate));
      } else {
        m.notes.push_back("gyro bias: none subtracted; no still second in the IMU (" + still.refused + ")");
      }
      for (const std::string& n : m.notes) spdlog::info("{}", n);
      if (still.found && m.gyro_bias == still.gyro_mean)
        spdlog::info("gyro bias {:.5f},{:.5f},{:.5f} rad/s (IMU frame) subtracted: {}", m.gyro_bias.x(),
                     m.gyro_bias.y(), m.gyro_bias.z(), m.gyro_note);
    }
    if (!m.gyro_bias.isZero(0.0))
      for (ImuSample& sample : imu) sample.gyro -= m.gyro_bias;
    m.gyro = GyroTrack(imu, m.calib.R_cam_imu, m.calib.time_offset, m.config.gyro);
    if (m.config.accelerometer.use) m.setUpAccelerometer(imu, still);
  }
  if (!m.inputs.truth_labels.empty() && m.inputs.truth_labels != "none") {
    const std::string events_file =
        fs::is_directory(in.events) ? sequenceFilePath(in.events, sequence_file::kEvents) : in.events;
    m.truth = TruthLabels::read(events_file, m.inputs.truth_labels, m.config.reader);
  }
  if (!m.inputs.groundtruth.empty()) {
    auto poses = readPosesText(m.inputs.groundtruth, m.config.reader);
    m.n_poses = poses.size();
    if (!poses.empty())
      m.gt = std::make_unique<GtVelocityEstimator>(std::move(poses), m.calib.T_body_cam,
                                                         m.config.groundtruth);
  }
}

SequenceRunner::~SequenceRunner() = default;

bool SequenceRunner::hasGroundTruth() const { return impl_->gt != nullptr; }
bool SequenceRunner::hasImu() const { return !impl_->gyro.empty(); }

std::vector<std::string> SequenceRunner::describe() const {
  const Impl& m = *impl_;
  std::vector<std::string> d;
  d.push_back("events: " + m.reader->path() + " (" + toString(m.reader->format()) + ")");
  d.push_back("calibration: " + m.inputs.calib + " (" + std::to_string(m.calib.camera.width) + "x" +
              std::to_string(m.calib.camera.height) +
              (m.size_assumed ? " assumed: neither the calibration nor the recording states an image size; "
                                "set input.width / input.height" : "") +
              ", " + toString(m.calib.camera.distortion) + ")");
  if (m.config.omega_source == OmegaSource::Fixed)
    d.push_back("angular velocity: fixed by the configuration (motion.fixed_omega)");
  else {
    std::string g = "gyroscope: " + std::to_string(m.n_imu) + " samples";
    if (!m.gyro_bias.isZero(0.0))
      g += fmt::format(", bias {:.5f},{:.5f},{:.5f} rad/s (IMU frame; {:.2f} deg/s) subtracted: {}", m.gyro_bias.x(),
                       m.gyro_bias.y(), m.gyro_bias.z(), m.gyro_bias.norm() * 180.0 / M_PI, m.gyro_note);
    d.push_back(g);
    d.insert(d.end(), m.notes.begin(), m.notes.end());
    if (!m.accelerometer_note.empty()) d.push_back(m.accelerometer_note);
  }
  d.push_back(m.gt ? "ground truth: " + m.inputs.groundtruth + " (" + std::to_string(m.n_poses) + " poses)"
                   : std::string("ground truth: none (no metrics)"));
  return d;
}

void SequenceRunner::dumpWindows(WindowDumpContext context) {
  Impl& m = *impl_;
  context.calib = fs::absolute(m.inputs.calib).string();
  context.seed = m.config.seed;
  context.gyro_integrated =
      m.config.omega_source == OmegaSource::Gyro && m.config.motion == MotionModelKind::GyroIntegrated;
  m.dump = std::move(context);
}

WindowRecord SequenceRunner::processWindow(std::uint64_t index, double t0, double t1,
                                           const std::vector<Event>& events, std::optional<double> probe_px,
                                           int cluster_threads) const {
  const Impl& m = *impl_;
  const RunConfig& cfg = m.config;
  ClusterOptions cluster_options = cfg.cluster;
  if (cluster_threads > 0) cluster_options.threads = cluster_threads;
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
    // The last window, cut by the end of the data, may run past the ground
    // truth's last pose: its truth is then the mean over the span its events cover.
    GtVelocity g = m.gt->window(t0, t1);
    if (g.status == GtStatus::NotCovered && !events.empty() && events.back().t < t1)
      g = m.gt->window(t0, events.back().t);
    if (g.ok() && g.v_cam.norm() > 1e-9) {
      rec.has_gt = true;
      rec.gt_speed = g.v_cam.norm();
      rec.gt = g.v_cam / rec.gt_speed;
    }
  }
  rec.times.groundtruth = secondsSince(start);

  // The angular velocity for the window.
  MotionModel motion = MotionModel::constantTwist(cfg.fixed_omega, t0);
  if (!m.motionFor(t0, t1, motion, rec.omega, rec.window_status)) return rec;
  rec.has_omega = true;

  // Clustering in pixel space-time.
  start = Clock::now();
  auto bearing = [&](const Vec2& p) { return m.bearing(p); };
  ClusterResult clusters =
      cluster_options.derotate
          ? clusterEvents(derotateEvents(events, bearing, m.calib.camera, motion, 0.5 * (t0 + t1)), cluster_options)
          : clusterEvents(events, cluster_options);
  const LineSplitReport cut =
      splitByMovingLines(events, clusters, bearing, m.calib.camera.focal(), &motion, cluster_options);
  rec.times.cluster = secondsSince(start);
  if (cut.n_recovered > 0)
    spdlog::debug("window {}: {} clusters of {} events recovered from the left-out events (cluster.recover_cell_px)",
                  index, cut.n_recovered, cut.n_recovered_events);
  const ClusterLosses& left = clusters.left_out;
  rec.n_events_clustered = clusters.n_clustered;
  rec.left_out = left;
  spdlog::debug("window {}: {} of {} events clustered; left out: {} invalid, {} in no region, {} in regions under "
                "cluster.min_cluster_size, {} failing the checks, {} off the planes, {} off the moving lines",
                index, clusters.n_clustered, clusters.n_events, left.invalid, left.no_region, left.small_region,
                left.failed_checks, left.off_planes, left.off_moving_lines);
  // The clusters `celc solve` reproduces the window's answers from (dump_windows).
  auto dump = [&](const std::vector<int>& labels) {
    if (!m.dump) return;
    const GyroWindow gw = cfg.omega_source == OmegaSource::Gyro && !m.gyro.empty() ? m.gyro.window(t0, t1)
                                                                                 : GyroWindow{};
    dumpWindow(*m.dump, index, t0, events, labels, &gw, rec.omega);
  };
  if (clusters.status != ClusterStatus::Ok) {
    dump(clusters.labels);
    if (m.truth) m.measureAgainstTruth(rec, events, clusters.labels, motion);
    rec.window_status = toString(clusters.status);
    return rec;
  }

  // Undistorted bearings and boundary lines per cluster.
  start = Clock::now();
  const CameraModel& cam = m.calib.camera;
  ObservationReport report;
  std::vector<std::vector<int>> members;  // the observations' events (restoreObservationEvents)
  WindowObservations obs =
      toObservations(events, clusters, bearing, cam.focal(), cfg.observations, &motion, &report, &members,
                     cluster_options.threads);
  rec.n_clusters = report.n_used;  // with lines; npt also gets the others
  rec.n_line_fit_failed = report.n_line_fit_failed;
  for (std::size_t k = 0; k < report.failed_ids.size(); ++k) {
    const ClusterLines& l = report.failed_lines[k];
    spdlog::debug("window {}: cluster {}: lines not fitted (l1 {}, {} events, {:.2f} px, {:.1f} px long; l3 {}, "
                  "{} events, {:.2f} px, {:.1f} px long); npt only",
                  index, report.failed_ids[k], toString(l.l1.status), l.l1.n_events, l.l1.rms_px,
                  l.l1.length_px, toString(l.l3.status), l.l3.n_events, l.l3.rms_px, l.l3.length_px);
  }
  if (report.n_merged > 0)
    spdlog::debug("window {}: {} clusters joined into others as fragments of one edge (observations.merge_px)",
                  index, report.n_merged);
  rec.times.lines = secondsSince(start);
  rec.translation_px = lineTranslationPx(obs, motion, t0, t1);

  // The parallax policy grew the window as far as it could (to
  // windows.max_seconds, or to the end of the data) and its lines still show
  // too little translation: no method is asked for a direction. D is the
  // whole window's (all its events clustered), or the probe's that chose the
  // length where the whole window's could not be measured: a probe clusters
  // a sparse subset, whose fragments show less of the lines' motion.
  const double shown_px = std::isfinite(rec.translation_px) ? rec.translation_px
                          : probe_px                         ? *probe_px
                                                             : NAN;
  if (probe_px && std::isfinite(shown_px) && shown_px < cfg.parallax.no_parallax_px) {
    for (MethodRow& row : rec.rows) {
      row.result.status = SolveStatus::Degenerate;
      row.result.degeneracy = Degeneracy::NoParallax;
      row.result.message = fmt::format("the lines moved {:.1f} px in {:.3f} s, less than windows.no_parallax_px = {:g}",
                                       shown_px, t1 - t0, cfg.parallax.no_parallax_px);
    }
    spdlog::debug("window {}: {}", index, rec.rows.front().result.message);
    dump(clusters.labels);
    if (m.truth) m.measureAgainstTruth(rec, events, report.event_clusters, motion);
    return rec;
  }
  start = Clock::now();
  const SampleSeeds seeds{cfg.seed + index, cfg.seed + index};  // windows draw different subsets
  // The clusters redrawn under the witness's first answer, where kept; then
  // every method on the window's final clusters.
  // The final clusters, before fragments join: kept for the dump only.
  std::vector<int> solved_labels;
  if (m.dump) solved_labels = std::move(clusters.labels);
  clusters = ClusterResult();  // the observations hold what the solvers need
  // The witness's estimates on the final clusters, which the methods share (SharedSolves).
  SharedSolves solves;
  if (const std::optional<Method> witness = m.redrawWitness(cluster_options)) {
    SolverResult answer = solveMethods(obs, motion, {*witness}, m.witnessOptions(), seeds, solves).front();
    rec.times.solve = secondsSince(start);
    start = Clock::now();
    std::vector<int> drawn_from;
    MotionLines lines;
    for (int round = 0; round < cluster_options.motion_redraw_rounds && answer.ok(); ++round) {
      if (!m.redrawUnderMotion(events, motion, seeds, cluster_options, index, *witness, answer,
                               m.dump ? &solved_labels : nullptr, report, obs, members, solves, drawn_from, lines))
        break;
      rec.n_clusters = report.n_used;
      rec.n_line_fit_failed = report.n_line_fit_failed;
    }
    rec.times.redraw = secondsSince(start);
    start = Clock::now();
  }
  obs.accelerometer = m.accelerometer.window(t0, t1, motion.referenceTime());
  const std::vector<SolverResult> results =
      solveMethods(obs, motion, cfg.methods, cfg.solver, seeds, solves, cluster_options.threads);
  rec.times.solve += secondsSince(start);
  dump(solved_labels);
  if (m.truth) m.measureAgainstTruth(rec, events, report.event_clusters, motion);
  for (size_t i = 0; i < cfg.methods.size(); ++i) {
    MethodRow& row = rec.rows[i];
    row.result = results[i];
    // An answer with a note (an estimated rate offset, an answered ambiguous nullspace).
    if (row.result.ok() && !row.result.message.empty())
      spdlog::debug("window {}: {}: {}", index, toString(cfg.methods[i]), row.result.message);
    if (row.result.ok() && rec.has_gt) {
      row.has_metrics = true;
      row.eps = directionDistance(rec.gt, row.result.v);
      row.phi = directionAngle(rec.gt, row.result.v);
    }
  }
  return rec;
}

void RunClusterTotals::add(const WindowRecord& rec) {
  auto count = [](int n) { return static_cast<std::uint64_t>(std::max(n, 0)); };
  const ClusterLosses& l = rec.left_out;
  clustered += count(rec.n_events_clustered);
  invalid += count(l.invalid), no_region += count(l.no_region), small_region += count(l.small_region);
  failed_checks += count(l.failed_checks), off_planes += count(l.off_planes);
  off_moving_lines += count(l.off_moving_lines);
}

RunStats SequenceRunner::run(int threads, const WindowFilter& filter,
                             const std::function<void(const WindowRecord&)>& sink,
                             const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  Impl& m = *impl_;
  RunStats stats;
  const auto start = Clock::now();
  struct Job {
    std::uint64_t index = 0;
    double t0 = 0.0, t1 = 0.0;
    std::vector<Event> events;
    std::optional<double> probe_px;  ///< the parallax policy's D (window_policy.hpp); nullopt: other policies
  };
  const RunConfig& cfg = m.config;
  const bool parallax = cfg.window_policy == WindowPolicy::Parallax;
  // The parallax policy reads steps of step_seconds and joins them into windows.
  WindowOptions source_options = cfg.windows;
  if (parallax) {
    source_options.events_per_window = 0;
    source_options.seconds_per_window = cfg.parallax.step_seconds;
    source_options.overlap = 0.0;
    source_options.keep_partial = true;  // the last step, whatever it holds; judged below
  }
  WindowSource source(*m.reader, source_options);
  EventWindow window;
  // The cores stay busy where the windows alone would leave them idle: a
  // probe while no window is worked on or waiting (the first window's), the
  // last window to start once every window is read, and a window that leaves
  // no room beside it for another of its size (windows.max_events_in_flight)
  // cluster with every worker's thread. The clusters do not depend on the
  // thread count.
  const int workers = resolveThreadCount(threads);
  const int all_threads = std::max(workers, cfg.cluster.threads);
  std::atomic<int> busy{0};           // windows being worked on
  std::atomic<int> waiting{0};        // windows read and not yet started
  std::atomic<bool> all_read{false};  // the producer has read its last window
  struct Busy {
    std::atomic<int>& n;
    explicit Busy(std::atomic<int>& count) : n(count) { ++n; }
    ~Busy() { --n; }
  };
  ParallaxWindowJoiner joiner(source, cfg.parallax, cfg.windows.partial_min_share,
                              [&](double t0, double t1, const std::vector<Event>& events) {
                                const auto t_probe = Clock::now();
                                const int probe_threads =
                                    workers > 1 && busy.load() == 0 && waiting.load() == 0 ? all_threads : 0;
                                const double d = m.probeTranslation(t0, t1, events, probe_threads);
                                stats.seconds_probing += secondsSince(t_probe);
                                spdlog::debug("parallax window at {:.3f} s: {:.3f} s, {} events: D = {:.1f} px", t0,
                                              t1 - t0, events.size(), d);
                                return d;
                              },
                              [&](double t0, double t1) { return m.turnAngle(t0, t1); });
  auto nextWindow = [&](EventWindow& w) { return parallax ? joiner.next(w) : source.next(w); };
  // By count the number of windows per second of data depends on the event
  // rate: checked as windows arrive (by duration WindowOptions::validate did).
  double first_t0 = 0.0;
  auto checkWindowRate = [&](std::uint64_t n_windows, const EventWindow& w) {
    const WindowOptions& wo = m.config.windows;
    if (wo.events_per_window == 0) return;
    if (n_windows == 1) first_t0 = w.t0;
    const double span = w.t1 - first_t0;
    // The first window alone: a step of `step` events lasts about
    // span * step / n s; later: the windows so far over the data so far.
    const double n = static_cast<double>(wo.events_per_window);
    const double step = std::max(1.0, std::floor((1.0 - wo.overlap) * n));
    const double per_second = n_windows == 1 ? n / (step * span) : (n_windows - 1.0) / span;
    if (!(per_second <= wo.max_windows_per_second)) {
      std::ostringstream e;
      e.precision(3);
      e << "windows.events = " << wo.events_per_window << ": " << per_second
        << " windows per second of data (at " << n_windows << (n_windows == 1 ? " window" : " windows")
        << "), more than windows.max_windows_per_second = " << wo.max_windows_per_second
        << "; use longer windows or raise the bound";
      throw std::runtime_error(e.str());
    }
  };
  // Windows read and not yet written: a bound on the memory held, by count
  // and by the events they hold (windows.max_events_in_flight).
  const std::size_t max_in_flight = static_cast<std::size_t>(resolveThreadCount(threads)) + 2;
  const std::size_t max_events = cfg.max_events_in_flight;
  const JobWeightBound<Job> by_events{max_events, [](const Job& job) { return job.events.size(); }};
  orderedParallelMap<Job, WindowRecord>(
      threads, max_in_flight, by_events,
      [&](Job& job) {  // the next wanted window, read on this thread
        for (;;) {
          const auto t_read = Clock::now();
          const bool more = nextWindow(window);
          stats.seconds_reading += secondsSince(t_read);
          if (!more) {
            all_read = true;
            return false;
          }
          stats.windows_read++;
          stats.events_read += window.events.size();
          checkWindowRate(stats.windows_read, window);
          const auto idx = static_cast<std::int64_t>(window.index);
          const bool wanted = idx > filter.after && filter.shard_count > 0 &&
                              idx % filter.shard_count == filter.shard_index;
          if (!wanted) continue;
          job.index = window.index;
          job.t0 = window.t0;
          job.t1 = window.t1;
          job.events = std::move(window.events);
          job.probe_px = parallax ? std::optional<double>(joiner.translationPx()) : std::nullopt;
          window.events = {};
          ++waiting;
          return true;
        }
      },
      [&](Job& job) {
        const Busy working(busy);
        const bool last = --waiting == 0 && all_read.load();
        const bool alone = max_events > 0 && 2 * job.events.size() > max_events;
        return processWindow(job.index, job.t0, job.t1, job.events, job.probe_px,
                             workers > 1 && (last || alone) ? all_threads : 0);
      },
      [&](WindowRecord& rec) {  // in window order, on this thread
        stats.windows_processed++;
        stats.events_processed += rec.n_events;
        stats.stage_seconds.cluster += rec.times.cluster;
        stats.stage_seconds.lines += rec.times.lines;
        stats.stage_seconds.solve += rec.times.solve;
        stats.stage_seconds.truth += rec.times.truth;
        stats.stage_seconds.redraw += rec.times.redraw;
        stats.stage_seconds.groundtruth += rec.times.groundtruth;
        stats.clusters_line_fit_failed += static_cast<std::uint64_t>(rec.n_line_fit_failed);
        stats.clustering.add(rec);
        sink(rec);
        if (progress) progress(stats.windows_processed, stats.events_processed);
      });
  stats.reader_warnings = m.reader->warnings().total();
  stats.tail = parallax ? joiner.tail() : source.tail();
  stats.seconds_total = secondsSince(start);
  const StageTimes& st = stats.stage_seconds;
  spdlog::debug("stage seconds: reading {:.3f} (of which parallax probes {:.3f}), clustering {:.3f}, "
                "undistortion+lines {:.3f}, solvers {:.3f}, redraws {:.3f}, ground truth {:.3f}, truth labels {:.3f}; "
                "{} events in {:.3f} s",
                stats.seconds_reading, stats.seconds_probing, st.cluster, st.lines, st.solve, st.redraw,
                st.groundtruth, st.truth, stats.events_processed, stats.seconds_total);
  return stats;
}

}  // namespace celc
