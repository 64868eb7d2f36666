// celc.solve: the solvers on events already labelled by cluster, the path of
// `celc solve` (cluster/to_observations.hpp, solver/solver.hpp).
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>

#include "celc/cluster/to_observations.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/io/calibration.hpp"
#include "config.hpp"

namespace celc::py {
namespace {

using Clock = std::chrono::steady_clock;

CameraModel cameraFrom(const pyb::handle& calib, bool normalized, double focal) {
  CameraModel cam;
  if (calib.is_none()) {
    if (!normalized) throw pyb::value_error("solve: pixel events need calib= (a file or a dict), or normalized=True");
    cam.fx = cam.fy = focal;
  } else if (pyb::isinstance<pyb::dict>(calib)) {
    // The last camera dict is remembered (calls under the GIL): a loop over
    // windows with one camera parses it once.
    static std::string last_key;
    static CameraModel last_camera;
    std::string key;
    for (const std::string& a : assignments(calib)) key += a + "\n";
    if (key == last_key && !key.empty()) return last_camera;
    applyDict(calib, "solve(calib)", [&](FieldVisitor& v) { describe(v, cam); });
    if (std::string err = cam.validate(); !err.empty()) {
      while (!err.empty() && (err.back() == ' ' || err.back() == ';')) err.pop_back();
      throw ConfigError("solve(calib): " + err);
    }
    last_key = key;
    last_camera = cam;
  } else {
    cam = loadCalibration(existingPath(calib)).camera;
  }
  return cam;
}

// Gyroscope rates (N, 4): t [s], wx, wy, wz [rad/s], camera frame.
struct GyroTrack {
  std::vector<double> times;
  std::vector<Vec3> rates;
};
GyroTrack gyroTrack(const pyb::handle& gyro) {
  auto g = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(gyro);
  if (!g || g.ndim() != 2 || g.shape(1) != 4 || g.shape(0) < 1)
    throw pyb::value_error("solve: gyro must be an (N, 4) array of t, wx, wy, wz");
  GyroTrack track;
  for (pyb::ssize_t i = 0; i < g.shape(0); ++i) {
    if (i > 0 && !(g.at(i, 0) > g.at(i - 1, 0)))
      throw pyb::value_error("solve: gyro row " + std::to_string(i) + ": time does not increase");
    track.times.push_back(g.at(i, 0));
    track.rates.emplace_back(g.at(i, 1), g.at(i, 2), g.at(i, 3));
  }
  return track;
}

pyb::dict resultDict(const SolverResult& r) {
  pyb::dict d;
  d["status"] = toString(r.status);
  // The reason as windows.csv spells it: the degeneracy, else the status.
  d["reason"] = r.status == SolveStatus::Degenerate ? toString(r.degeneracy) : r.ok() ? "" : toString(r.status);
  d["message"] = r.message;
  if (r.ok()) d["v"] = pyb::array_t<double>(3, r.v.data());
  else d["v"] = pyb::none();
  d["sigma_deg"] = r.sigma_deg;
  d["parallax"] = r.parallax;
  d["n_lines"] = r.n_lines;
  d["time_us"] = r.time_us;
  d["residual_px"] = r.residual_px;
  d["sign_margin"] = r.sign_margin;
  d["iterations"] = r.iterations;
  return d;
}

// The C++ part of solve() is timed for the overhead benchmark (`cpp_seconds`).
pyb::dict solveImpl(const pyb::object& events, const pyb::object& labels, const pyb::object& omega,
                    const pyb::object& gyro, const pyb::object& calib, bool normalized, double focal,
                    const pyb::object& methods, const pyb::object& config, const pyb::object& set,
                    double* cpp_seconds) {
  const RunConfig cfg = runConfig(config, set, methods, "solve");
  const CameraModel cam = cameraFrom(calib, normalized, focal);
  std::vector<Event> ev = eventsFromPython(events);
  auto lab = pyb::array_t<int, pyb::array::c_style | pyb::array::forcecast>::ensure(labels);
  if (!lab || lab.ndim() != 1 || static_cast<std::size_t>(lab.shape(0)) != ev.size())
    throw pyb::value_error("solve: labels must be a 1-D integer array, one per event (" + std::to_string(ev.size()) +
                           ")");
  std::vector<int> lb(lab.data(), lab.data() + lab.shape(0));
  if (omega.is_none() && gyro.is_none())
    throw pyb::value_error("solve: give omega=[wx, wy, wz] [rad/s, camera frame] ([0, 0, 0] for a camera that "
                           "does not turn) or gyro=(N, 4) array");
  if (!omega.is_none() && !gyro.is_none()) throw pyb::value_error("solve: give omega or gyro, not both");
  Vec3 w = Vec3::Zero();
  if (!omega.is_none()) {
    auto o = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(omega);
    if (!o || o.size() != 3) throw pyb::value_error("solve: omega must hold three numbers wx, wy, wz [rad/s]");
    w = Vec3(o.data()[0], o.data()[1], o.data()[2]);
  }
  const GyroTrack track = gyro.is_none() ? GyroTrack{} : gyroTrack(gyro);
  const bool has_gyro = !gyro.is_none();
  std::vector<SolverResult> results;
  {
    pyb::gil_scoped_release nogil;
    // What a C++ caller runs (timed, temporaries' destruction included).
    const auto start = Clock::now();
    {
      const BearingFunction bearing = [&](const Vec2& p) {
        return normalized ? Vec3(p.x(), p.y(), 1.0) : cam.bearing(p);
      };
      // Reference time: the first labelled event (as `celc solve`).
      const LabelledObservations in =
          observeLabelledEvents(ev, lb, bearing, cam.focal(), cfg.observations, [&](double t_first) {
            return has_gyro ? MotionModel::gyroIntegrated(track.times, track.rates, t_first)
                            : MotionModel::constantTwist(w, t_first);
          });
      results = solveMethods(in.observations, in.motion, cfg.methods, cfg.solver, SampleSeeds{cfg.seed, cfg.seed});
    }
    if (cpp_seconds) *cpp_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  }
  pyb::dict out;
  for (std::size_t i = 0; i < results.size(); ++i) out[pyb::str(toString(cfg.methods[i]))] = resultDict(results[i]);
  return out;
}

}  // namespace

void bindSolve(pyb::module_& m) {
  auto solve = [](const pyb::object& events, const pyb::object& labels, const pyb::object& omega,
                  const pyb::object& gyro, const pyb::object& calib, bool normalized, double focal,
                  const pyb::object& methods, const pyb::object& config, const pyb::object& set) {
    return solveImpl(events, labels, omega, gyro, calib, normalized, focal, methods, config, set, nullptr);
  };
  m.def("solve", solve, pyb::arg("events"), pyb::arg("labels"), pyb::kw_only(), pyb::arg("omega") = pyb::none(),
        pyb::arg("gyro") = pyb::none(), pyb::arg("calib") = pyb::none(), pyb::arg("normalized") = false,
        pyb::arg("focal") = 320.0, pyb::arg("methods") = pyb::none(), pyb::arg("config") = pyb::none(),
        pyb::arg("set") = pyb::none(),
        R"(The solvers on events labelled by cluster: what `celc solve` does.

events: structured array with t [s], x, y [px] (EVENT_DTYPE, or any with
those fields); labels: cluster id per event (int, -1 = unassigned).
omega: constant angular velocity wx, wy, wz [rad/s], camera frame ([0, 0, 0]
for a camera that does not turn); or gyro: (N, 4) array t [s], wx, wy, wz
[rad/s], camera frame (the gyro-integrated model). One of the two is required. The reference time is the first labelled event.
calib: calibration file (docs/formats.md, calib.txt) or a dict of the
camera schema (width, height, fx, fy, cx, cy, distortion_model, distortion); or
normalized=True for normalised coordinates (focal [px] scales thresholds).
config: run configuration (YAML path or dict: its lines, observations,
solver, methods, seed); set: overrides {"key.path": value};
methods: list or "celc,celc_opt" (default: the configuration's, all six).

Returns {method: {"status", "reason", "message", "v" (unit direction,
reference camera frame; None unless ok), "sigma_deg" (nan when not
computed), "parallax", "n_lines", "time_us", "residual_px", "sign_margin",
"iterations"}} in method order. The GIL is released while solving.)");
  m.def("_solve_timed",
        [](const pyb::object& events, const pyb::object& labels, const pyb::object& omega, const pyb::object& calib,
           const pyb::object& methods) {
          double seconds = 0.0;
          pyb::dict r = solveImpl(events, labels, omega, pyb::none(), calib, false, 320.0, methods, pyb::none(),
                                  pyb::none(), &seconds);
          return pyb::make_tuple(r, seconds);
        },
        pyb::arg("events"), pyb::arg("labels"), pyb::arg("omega"), pyb::arg("calib"), pyb::arg("methods"),
        "solve() returning (results, seconds spent in the C++ call): for the overhead benchmark.");
}

}  // namespace celc::py
