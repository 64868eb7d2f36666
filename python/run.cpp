// celc.run: `celc run` on one recording, the rows of windows.csv returned as
// columns (pipeline/sequence_runner.hpp, pipeline/run_output.hpp).
#include <pybind11/stl.h>

#include <cmath>
#include <cstdlib>
#include <optional>
#include <set>
#include <sstream>

#include "celc/eval/run_tables.hpp"
#include "celc/pipeline/run_output.hpp"
#include "celc/pipeline/sequence_runner.hpp"
#include "config.hpp"

namespace celc::py {
namespace {

using namespace pybind11::literals;

constexpr int kMaxThreads = 1024;  // as `celc run --threads`

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// The windows.csv lines as columns: text columns as str arrays, counts as
// int64 (-1 where the cell is empty), the rest float64 (NaN where empty).
pyb::dict columns(const std::vector<std::string>& lines) {
  static const std::set<std::string> text{"method", "status", "reason", "sigma_rule", "model"};
  static const std::set<std::string> counts{"window",          "n_events", "n_clusters",    "n_lines",
                                            "impure_clusters", "edges",    "edges_complete"};
  const std::vector<std::string> names = splitCsv(windowsCsvHeader());
  std::vector<std::vector<std::string>> cells;
  cells.reserve(lines.size());
  for (const std::string& l : lines) {
    cells.push_back(splitCsv(l));
    if (cells.back().size() != names.size())
      throw std::logic_error("run: a windows.csv row with " + std::to_string(cells.back().size()) + " cells");
  }
  pyb::module_ np = pyb::module_::import("numpy");
  pyb::dict out;
  const auto n = static_cast<pyb::ssize_t>(cells.size());
  for (std::size_t c = 0; c < names.size(); ++c) {
    const std::string& name = names[c];
    if (text.count(name)) {
      pyb::list values;
      for (const auto& row : cells) values.append(row[c]);
      out[pyb::str(name)] = np.attr("array")(values, "dtype"_a = "U");
    } else if (counts.count(name)) {
      pyb::array_t<std::int64_t> a(n);
      for (pyb::ssize_t i = 0; i < n; ++i) {
        const std::string& cell = cells[static_cast<std::size_t>(i)][c];
        a.mutable_at(i) = cell.empty() ? -1 : std::strtoll(cell.c_str(), nullptr, 10);
      }
      out[pyb::str(name)] = a;
    } else {
      pyb::array_t<double> a(n);
      for (pyb::ssize_t i = 0; i < n; ++i) {
        const std::string& cell = cells[static_cast<std::size_t>(i)][c];
        a.mutable_at(i) = cell.empty() ? NAN : std::strtod(cell.c_str(), nullptr);
      }
      out[pyb::str(name)] = a;
    }
  }
  return out;
}

std::string optionalPath(const pyb::handle& p) { return p.is_none() ? std::string() : existingPath(p); }

pyb::dict run(const pyb::object& path, const pyb::object& config, const pyb::object& set,
              const pyb::object& methods, const pyb::object& calib, const pyb::object& groundtruth,
              const pyb::object& imu, std::optional<std::size_t> window_events,
              std::optional<double> window_seconds, const pyb::object& omega, int threads) {
  RunConfig c = runConfig(config, set, methods, "run");
  if (threads < 0 || threads > kMaxThreads)
    throw pyb::value_error("run: threads=" + std::to_string(threads) + ": expected 0 (all cores) to " +
                           std::to_string(kMaxThreads));
  if (window_events && window_seconds) throw pyb::value_error("run: give window_events or window_seconds, not both");
  if (window_events) {  // as --window-events: the events policy
    c.window_policy = WindowPolicy::Events;
    c.windows.events_per_window = *window_events;
    c.windows.seconds_per_window = 0.0;
  }
  if (window_seconds) {  // as --window-seconds: the seconds policy
    c.window_policy = WindowPolicy::Seconds;
    c.windows.seconds_per_window = *window_seconds;
    c.windows.events_per_window = 0;
  }
  if (!omega.is_none()) {
    auto o = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(omega);
    if (!o || o.size() != 3) throw pyb::value_error("run: omega must hold three numbers wx, wy, wz [rad/s]");
    c.omega_source = OmegaSource::Fixed;
    c.fixed_omega = Vec3(o.data()[0], o.data()[1], o.data()[2]);
  }
  // Windows run in parallel: each window's clustering on one thread (result-neutral, as `celc run`).
  if (threads != 1) c.cluster.threads = 1;
  if (const std::string err = c.validate(); !err.empty()) throw ConfigError("run: configuration: " + err);

  RunInputs inputs{existingPath(path), optionalPath(calib), optionalPath(groundtruth), optionalPath(imu), ""};
  std::vector<std::string> lines;
  {
    pyb::gil_scoped_release nogil;
    defaultContainerInputs(inputs, c.reader);
    SequenceRunner runner(inputs, c);
    runner.run(threads, WindowFilter{}, [&](const WindowRecord& r) {
      for (std::string& l : windowsCsvLines(r)) lines.push_back(std::move(l));
    });
  }
  return columns(lines);
}

}  // namespace

void bindRun(pyb::module_& m) {
  m.def("run", &run, pyb::arg("path"), pyb::kw_only(), pyb::arg("config") = pyb::none(),
        pyb::arg("set") = pyb::none(), pyb::arg("methods") = pyb::none(), pyb::arg("calib") = pyb::none(),
        pyb::arg("groundtruth") = pyb::none(), pyb::arg("imu") = pyb::none(),
        pyb::arg("window_events") = pyb::none(), pyb::arg("window_seconds") = pyb::none(),
        pyb::arg("omega") = pyb::none(), pyb::arg("threads") = 0,
        R"(`celc run` on one recording, without an output folder: the rows of
windows.csv as a dict of numpy arrays, one entry per column in the file's
order (window, t_start, t_end, n_events, n_clusters, method, status, vx, vy,
vz, gt_vx, gt_vy, gt_vz, eps, phi, runtime_ms, reason, sigma_deg, parallax,
n_lines, wx, wy, wz, translation_px, then with truth labels purity,
impure_clusters, edges, edges_complete, coverage, noise_admitted, oracle_phi;
units in docs/running.md), one row per window and method.
The values are the file's text read back (same digits as windows.csv):
method / status / reason str arrays, window / n_events / n_clusters / n_lines /
impure_clusters / edges / edges_complete int64 (-1 where the file's cell is empty), the others float64 (NaN where empty).

path: RPG / UZH-FPV directory, events / aedat file, ROS bag or HDF5 (a bag's
camera and a container's poses are used unless calib / groundtruth say otherwise).
config: YAML path or dict over the run schema; set: {"key.path": value};
methods, window_events, window_seconds, omega (wx, wy, wz [rad/s], camera
frame, instead of the gyroscope), threads (0 = all cores): as the options
of `celc run`. The GIL is released while running.)");
}

}  // namespace celc::py
