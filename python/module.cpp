// The `celc` Python module: readers, solvers, runs and simulators of the
// library, with C++ errors as Python exceptions (docs/python.md).
#include <glog/logging.h>
#include <spdlog/spdlog.h>

#include <new>
#include <stdexcept>

#include "celc/io/event_reader.hpp"
#include "common.hpp"

namespace pyb = pybind11;

PYBIND11_MODULE(celc, m) {
  m.doc() = "celc: linear velocity direction of an event camera (Continuous Event-Line Constraint). "
            "Times in seconds, pixels origin top-left, camera frame x right, y down, z forward.";
  m.attr("__version__") = CELC_VERSION;
  // Library errors keep their one-line message: files -> OSError,
  // configuration and arguments -> ValueError, the rest -> RuntimeError.
  pyb::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const celc::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const celc::ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  // Ceres logs through glog: as in the CLI, only fatal errors (a refinement
  // that fails is a per-method status with Ceres' message).
  FLAGS_minloglevel = google::GLOG_FATAL;
  FLAGS_logtostderr = true;
  // Library logs (spdlog) go to stderr; warnings and errors only by default.
  spdlog::set_level(spdlog::level::warn);
  m.def("set_log_level", [](const std::string& level) {
    const auto l = spdlog::level::from_str(level);
    if (l == spdlog::level::off && level != "off")
      throw pyb::value_error("log level '" + level + "': expected trace, debug, info, warn, error or off");
    spdlog::set_level(l);
  }, pyb::arg("level"), "Level of the library's log on stderr: trace, debug, info, warn (default), error, off.");
  celc::py::bindReaders(m);
  celc::py::bindSolve(m);
  celc::py::bindRun(m);
  celc::py::bindSim(m);
}
