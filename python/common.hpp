#pragma once
// Shared by the binding files of the `celc` Python module: the numpy layouts of
// the library's records, and options given as Python dicts.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc::py {

namespace pyb = pybind11;

/// The structured dtype of celc::Event, byte for byte:
/// t float64 [s], x float32 [px], y float32 [px], p bool (ON), itemsize 24.
pyb::dtype eventDtype();
/// The structured dtype of celc::ImuSample: t float64 [s], gyro (3,) float64
/// [rad/s], acc (3,) float64 [m/s^2], IMU frame, itemsize 56.
pyb::dtype imuDtype();

/// A numpy array over `v`'s buffer without copying: the vector moves to the
/// heap and a capsule owning it becomes the array's base.
template <class T>
pyb::array adoptVector(std::vector<T>&& v, const pyb::dtype& dtype) {
  auto* owned = new std::vector<T>(std::move(v));
  pyb::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return pyb::array(dtype, {static_cast<pyb::ssize_t>(owned->size())},
                    {static_cast<pyb::ssize_t>(sizeof(T))}, owned->data(), owner);
}

/// Events from a numpy structured array (or any object whose items `t`, `x`,
/// `y` and optionally `p` give 1-D arrays of one length). Our own dtype is read
/// in place; other layouts are converted field by field (one copy).
std::vector<Event> eventsFromPython(const pyb::handle& events);

/// A Python value as a YAML flow value: bool -> true/false, numbers at
/// round-trip precision, str as a quoted scalar, sequences and numpy arrays
/// as [a, b], dicts as {k: v}. Throws ValueError for other types.
std::string yamlValue(const pyb::handle& value);
/// Applies options given as a dict onto a schema, key by key: nested dicts
/// or dotted keys ({"solver": {"linear": {"huber_k": 2}}} or
/// {"solver.linear.huber_k": 2}). `origin` names them in error messages.
void applyDict(const pyb::handle& options, const std::string& origin, const Describe& describe);
/// `key.path=value` assignments from a dict (dotted or nested) or from a list
/// of "key=value" strings, in order.
std::vector<std::string> assignments(const pyb::handle& options);

/// A str or os.PathLike as a path string.
std::string pathString(const pyb::handle& path);
/// The same for a path that must exist: FileNotFoundError (an OSError)
/// "PATH: no such file or directory" otherwise.
std::string existingPath(const pyb::handle& path);

void bindReaders(pyb::module_& m);
void bindSolve(pyb::module_& m);
void bindRun(pyb::module_& m);
void bindSim(pyb::module_& m);

}  // namespace celc::py
