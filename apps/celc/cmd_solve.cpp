// `celc solve`: the solvers alone on events already labelled by cluster.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "celc/config/config.hpp"
#include "celc/core/text.hpp"
#include "celc/geometry/camera.hpp"
#include "celc/io/calibration.hpp"
#include "celc/io/labelled_events.hpp"
#include "celc/lines/line_fit.hpp"
#include "celc/solver/solver.hpp"
#include "commands.hpp"

namespace celc::app {
namespace {

struct SolveArgs {
  std::string events, calib, methods = "celc,celc_opt,celc_ml,ce3lc,npt", omega = "0,0,0", gyro;
  bool normalized = false, quiet = false, verbose = false;
  double focal = 320.0;
  double interval_ms = 5.0;
  double interval_fraction = 0.0;
  int min_events = 8;
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
  const auto events = readLabelledEvents(a.events);
  if (a.calib.empty() && !a.normalized)
    throw std::runtime_error("solve: pixel events need --calib FILE (or pass --normalized)");
  CameraModel cam;
  if (!a.calib.empty()) cam = loadCalibration(a.calib).camera;
  else cam.fx = cam.fy = a.focal;

  // Group by cluster (id >= 0), sorted by time.
  std::map<int, std::vector<LabelledEvent>> groups;
  for (const auto& e : events)
    if (e.cluster >= 0) groups[e.cluster].push_back(e);
  WindowObservations obs;
  obs.focal_px = cam.focal();
  LineFitOptions fit;
  fit.interval_s = a.interval_ms * 1e-3;
  fit.interval_fraction = a.interval_fraction;
  fit.min_events = a.min_events;
  if (const auto err = fit.validate(); !err.empty()) throw std::runtime_error("solve: " + err);
  double t_min = 1e300;
  for (auto& [id, evs] : groups) {
    std::sort(evs.begin(), evs.end(), [](const auto& x, const auto& y) { return x.t < y.t; });
    ClusterObservation c;
    c.id = id;
    for (const auto& e : evs) {
      c.times.push_back(e.t);
      c.bearings.push_back(a.normalized ? Vec3(e.x, e.y, 1.0) : cam.bearing(Vec2(e.x, e.y)));
    }
    if (!attachFittedLines(c, obs.focal_px, fit)) {
      spdlog::warn("cluster {}: too few events to fit its start and end lines; skipped", id);
      continue;
    }
    t_min = std::min(t_min, c.times.front());
    obs.clusters.push_back(std::move(c));
  }
  spdlog::info("solve: {} events, {} clusters with lines", events.size(), obs.clusters.size());
  if (obs.clusters.empty()) t_min = 0.0;
  const MotionModel motion = a.gyro.empty()
                                 ? MotionModel::constantTwist(parseVec3(a.omega, "--omega"), t_min)
                                 : loadGyro(a.gyro, t_min);
  const auto methods = parseMethodList(a.methods);
  const auto results = solveMethods(obs, motion, methods, SolverOptions{});
  std::cout << "method,status,vx,vy,vz,runtime_us\n";
  for (size_t i = 0; i < methods.size(); ++i) {
    const auto& r = results[i];
    std::cout << toString(methods[i]) << "," << toString(r.status) << ",";
    if (r.ok()) std::cout << fmt::format("{:.9f},{:.9f},{:.9f}", r.v.x(), r.v.y(), r.v.z());
    else std::cout << ",,";
    std::cout << fmt::format(",{:.1f}\n", r.time_us);
    if (!r.ok()) spdlog::info("{}: {} ({})", toString(methods[i]), toString(r.status), r.message);
  }
}

}  // namespace

void registerSolve(CLI::App& app) {
  auto a = std::make_shared<SolveArgs>();
  auto* cmd = app.add_subcommand(
      "solve",
      "Solvers alone on labelled events (CSV header t,x,y,cluster; seconds, pixels; cluster -1 = "
      "unassigned). Fits each cluster's l1/l3 (and l2) from its first/last events and prints "
      "method,status,vx,vy,vz,runtime_us to stdout (v: unit direction, camera frame).");
  cmd->add_option("events", a->events, "labelled events CSV")->required()->check(CLI::ExistingFile);
  cmd->add_option("--omega", a->omega, "constant angular velocity wx,wy,wz [rad/s], camera frame")
      ->capture_default_str();
  cmd->add_option("--gyro", a->gyro,
                  "gyroscope CSV t,wx,wy,wz [s, rad/s, camera frame]: gyro-integrated motion model")
      ->check(CLI::ExistingFile);
  cmd->add_option("--calib", a->calib, "calibration YAML (docs/calibration.md) or calib.txt")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--normalized", a->normalized, "x, y are normalised (undistorted) coordinates");
  cmd->add_option("--focal", a->focal, "focal length [px] for pixel thresholds with --normalized")
      ->capture_default_str();
  cmd->add_option("--methods", a->methods, "comma-separated methods")->capture_default_str();
  cmd->add_option("--interval-ms", a->interval_ms, "end-interval length for l1/l3 [ms]")
      ->capture_default_str();
  cmd->add_option("--interval-fraction", a->interval_fraction,
                  "end interval as a fraction of the cluster's duration (overrides --interval-ms)")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--min-events", a->min_events, "events an end interval needs (it slides inward)")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", a->quiet, "only warnings and errors on stderr");
  cmd->add_flag("-v,--verbose", a->verbose, "debug logging");
  cmd->callback([a]() { runSolve(*a); });
}

}  // namespace celc::app
