// `celc solve`: the solvers alone on events already labelled by cluster.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include "celc/cluster/to_observations.hpp"
#include "celc/config/config.hpp"
#include "celc/core/text.hpp"
#include "celc/core/yaml.hpp"
#include "celc/geometry/camera.hpp"
#include "celc/io/calibration.hpp"
#include "celc/io/labelled_events.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/solver/solver.hpp"
#include "commands.hpp"
#include "run_common.hpp"

namespace celc::app {
namespace {

struct SolveArgs {
  std::string events, calib, methods, omega, gyro, config;
  std::vector<std::string> sets;
  bool normalized = false, quiet = false, verbose = false;
  double focal = 320.0;
  std::optional<double> t_ref;  ///< the motion's reference time [s]; default the first clustered event
};

Vec3 parseVec3(const std::string& text, const std::string& what) {
  std::vector<double> v;
  for (const std::string& item : splitList(text, ',')) {
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::runtime_error(what + ": '" + text + "' is not three comma-separated numbers");
    }
  }
  if (v.size() != 3) throw std::runtime_error(what + ": '" + text + "' needs three numbers");
  return {v[0], v[1], v[2]};
}

// Gyroscope CSV `t,wx,wy,wz` (seconds, rad/s, camera frame) for the gyro-integrated model.
MotionModel loadGyro(const std::string& path, double t_ref) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<double> times;
  std::vector<Vec3> rates;
  std::string line;
  for (size_t no = 1; std::getline(in, line); ++no) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::stringstream ss(line);
    double t, x, y, z;
    if (!(ss >> t >> x >> y >> z))
      throw std::runtime_error(path + ":" + std::to_string(no) + ": expected t,wx,wy,wz");
    if (!times.empty() && !(t > times.back()))
      throw std::runtime_error(path + ":" + std::to_string(no) + ": time does not increase");
    times.push_back(t);
    rates.emplace_back(x, y, z);
  }
  if (times.empty()) throw std::runtime_error(path + ": no gyroscope samples");
  return MotionModel::gyroIntegrated(times, rates, t_ref);
}

void runSolve(const SolveArgs& a) {
  configureLogging(a.quiet, a.verbose);
  // The run configuration: its lines, observations and solver sections (the
  // pipeline's own defaults), then -c FILE and --set.
  RunConfig cfg = a.config.empty() ? RunConfig{} : loadRunConfig(a.config);
  applySets(a.sets, cfg);
  if (!a.methods.empty()) cfg.methods = parseMethodList(a.methods);
  if (const std::string err = cfg.validate(); !err.empty()) throw std::runtime_error("configuration: " + err);

  if (a.t_ref && !std::isfinite(*a.t_ref)) throw std::runtime_error("--t-ref: must be a finite time [s]");
  const auto labelled = readLabelledEvents(a.events);
  if (a.calib.empty() && !a.normalized)
    throw std::runtime_error("solve: pixel events need --calib FILE (or pass --normalized)");
  // No rotation is assumed silently: a turning camera solved as a still one
  // gives confident wrong answers.
  if (a.omega.empty() && a.gyro.empty())
    throw std::runtime_error("solve: give the angular velocity: --omega wx,wy,wz [rad/s, camera frame] "
                             "(0,0,0 for a camera that does not turn) or --gyro FILE");
  if (!a.omega.empty() && !a.gyro.empty()) throw std::runtime_error("solve: give --omega or --gyro, not both");
  CameraModel cam;
  if (!a.calib.empty()) cam = loadCalibration(a.calib).camera;
  else cam.fx = cam.fy = a.focal;

  // The labels as a clustering result, so that the pipeline's toObservations
  // builds the input; the motion's reference time is the first labelled event.
  std::vector<Event> events;
  std::vector<int> labels;
  events.reserve(labelled.size());
  labels.reserve(labelled.size());
  for (const auto& e : labelled) {
    events.push_back(Event{e.t, static_cast<float>(e.x), static_cast<float>(e.y), true});
    labels.push_back(e.cluster < 0 ? -1 : e.cluster);
  }
  // Event positions are floats: 3e-5 px at 300 px, 6e-8 in normalised units.
  const BearingFunction bearing = [&](const Vec2& p) {
    return a.normalized ? Vec3(p.x(), p.y(), 1.0) : cam.bearing(p);
  };
  const LabelledObservations in = observeLabelledEvents(
      events, labels, bearing, cam.focal(), cfg.observations, [&](double t_first) {
        const double t_ref = a.t_ref.value_or(t_first);
        return a.gyro.empty() ? MotionModel::constantTwist(parseVec3(a.omega, "--omega"), t_ref)
                              : loadGyro(a.gyro, t_ref);
      });
  const ClusterResult& clusters = in.clusters;
  const ObservationReport& report = in.report;
  const WindowObservations& obs = in.observations;
  auto listed = [](const std::vector<int>& ids, int id) { return std::find(ids.begin(), ids.end(), id) != ids.end(); };
  for (std::size_t k = 0; k < clusters.clusters.size(); ++k)
    if (!listed(report.used_ids, clusters.clusters[k].id) && !listed(report.merged_ids, clusters.clusters[k].id))
      spdlog::warn("cluster {}: not used by the line methods (fewer than {} events, or its start and end "
                   "lines could not be fitted; npt uses it when it has the events)",
                   clusters.clusters[k].id, cfg.observations.min_events);
  spdlog::info("solve: {} events, {} clusters with lines ({} fragments of an edge joined into them, "
               "observations.merge_px), {} without (npt only)",
               events.size(), report.n_used, report.n_merged,
               obs.clusters.size() - static_cast<std::size_t>(report.n_used));
  const auto& methods = cfg.methods;
  const auto results = solveMethods(obs, in.motion, methods, cfg.solver, SampleSeeds{cfg.seed, cfg.seed});
  std::cout << "method,status,vx,vy,vz,runtime_us\n";
  for (size_t i = 0; i < methods.size(); ++i) {
    const auto& r = results[i];
    std::cout << toString(methods[i]) << "," << toString(r.status) << ",";
    if (r.ok()) std::cout << fmt::format("{:.9f},{:.9f},{:.9f}", r.v.x(), r.v.y(), r.v.z());
    else std::cout << ",,";
    std::cout << fmt::format(",{:.1f}\n", r.time_us);
    if (!r.ok()) spdlog::info("{}: {} ({})", toString(methods[i]), toString(r.status), r.message);
    else if (!r.message.empty()) spdlog::info("{}: {}", toString(methods[i]), r.message);
  }
}

}  // namespace

void registerSolve(CLI::App& app) {
  auto a = std::make_shared<SolveArgs>();
  auto* cmd = app.add_subcommand(
      "solve",
      "Solvers alone on labelled events (CSV header t,x,y,cluster; seconds, pixels; cluster -1 = "
      "unassigned). Builds each cluster's observation and lines as `celc run` does (its configuration: "
      "-c / --set) and prints method,status,vx,vy,vz,runtime_us to stdout (v: unit direction, in the camera frame at the "
      "first clustered event, the motion's reference time).");
  cmd->add_option("events", a->events, "labelled events CSV")->required()->check(CLI::ExistingFile);
  cmd->add_option("--omega", a->omega,
                  "constant angular velocity wx,wy,wz [rad/s], camera frame (0,0,0 for a camera that does not "
                  "turn); this or --gyro is required");
  cmd->add_option("--gyro", a->gyro,
                  "gyroscope CSV t,wx,wy,wz [s, rad/s, camera frame]: gyro-integrated motion model")
      ->check(CLI::ExistingFile);
  cmd->add_option("--calib", a->calib, "calibration YAML (docs/formats.md) or calib.txt")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--normalized", a->normalized, "x, y are normalised (undistorted) coordinates");
  cmd->add_option("--focal", a->focal, "focal length [px] for pixel thresholds with --normalized")
      ->capture_default_str();
  cmd->add_option("--t-ref", a->t_ref,
                  "reference time of the motion [s]: v is in the camera frame at this time (default: the first "
                  "clustered event; `celc run` uses the window's start)");
  cmd->add_option("-c,--config", a->config, "YAML run configuration (config/run.yaml): its lines, "
                  "observations, solver, methods and seed are used")->check(CLI::ExistingFile);
  cmd->add_option("--set", a->sets,
                  "override a configuration key, e.g. --set lines.interval_fraction=0.3 (repeatable; "
                  "`celc config --keys` lists them)");
  {
    RunConfig defaults;
    const Describe schema = [&](FieldVisitor& v) { describe(v, defaults); };
    cmd->add_option("--methods", a->methods,
                    "comma-separated celc,celc_opt,celc_ml,ce3lc,npt,celc_acc (or all): " + fieldHelp(schema, "methods"));
  }
  cmd->add_flag("-q,--quiet", a->quiet, "only warnings and errors on stderr");
  cmd->add_flag("-v,--verbose", a->verbose, "debug logging");
  cmd->callback([a]() { runSolve(*a); });
}

}  // namespace celc::app
