// celc.read_events, celc.read_imu, celc.write_events, celc.info: the
// library's readers and writers (io/event_reader.hpp, io/writers.hpp).
#include <pybind11/stl.h>

#include <sys/mman.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <new>
#include <optional>

#include "celc/io/event_reader.hpp"
#include "celc/io/writers.hpp"
#include "common.hpp"

namespace celc::py {
namespace {

ReaderOptions readerOptions(const pyb::handle& options, const std::string& origin) {
  ReaderOptions o;
  applyDict(options, origin, [&](FieldVisitor& v) { describe(v, o); });
  if (const std::string err = o.validate(); !err.empty()) throw ConfigError(origin + ": " + err);
  return o;
}

// A growable array of events in its own anonymous mapping, handed to numpy
// as it is. Growth is mremap (pages move, nothing is copied) and the mapping
// asks for transparent huge pages: first-touch page faults, not copying,
// dominate the cost of a large buffer on a virtual machine, and huge pages
// cut their number 512-fold (docs/python.md, "Memory").
class EventBuffer {
 public:
  EventBuffer() = default;
  EventBuffer(const EventBuffer&) = delete;
  EventBuffer& operator=(const EventBuffer&) = delete;
  ~EventBuffer() { unmap(data_, bytes_); }

  std::size_t size() const { return size_; }
  void append(const Event* events, std::size_t n) {
    if (n == 0) return;
    if ((size_ + n) * sizeof(Event) > bytes_) grow((size_ + n) * sizeof(Event));
    std::memcpy(static_cast<char*>(data_) + size_ * sizeof(Event), events, n * sizeof(Event));
    size_ += n;
  }
  void push(const Event& e) { append(&e, 1); }

  /// The events as a numpy array of EVENT_DTYPE owning the mapping.
  pyb::array release() {
    if (size_ == 0) return pyb::array(eventDtype(), {pyb::ssize_t(0)}, {static_cast<pyb::ssize_t>(sizeof(Event))});
    // Shrink the mapping to the pages in use (the tail was never touched).
    const std::size_t used = roundUp(size_ * sizeof(Event), kPage);
    if (used < bytes_) {
      ::munmap(static_cast<char*>(data_) + used, bytes_ - used);
      bytes_ = used;
    }
    auto* owned = new Mapping{data_, bytes_};
    data_ = nullptr;
    bytes_ = 0;
    const auto n = static_cast<pyb::ssize_t>(size_);
    size_ = 0;
    pyb::capsule owner(owned, [](void* p) {
      auto* m = static_cast<Mapping*>(p);
      unmap(m->data, m->bytes);
      delete m;
    });
    return pyb::array(eventDtype(), {n}, {static_cast<pyb::ssize_t>(sizeof(Event))}, owned->data, owner);
  }

 private:
  struct Mapping {
    void* data;
    std::size_t bytes;
  };
  static constexpr std::size_t kPage = 4096, kHuge = std::size_t(2) << 20;
  static std::size_t roundUp(std::size_t x, std::size_t to) { return (x + to - 1) / to * to; }
  static void unmap(void* p, std::size_t bytes) {
    if (p) ::munmap(p, bytes);
  }
  void grow(std::size_t need) {
    const std::size_t bytes = roundUp(std::max(need, std::max(2 * bytes_, kHuge)), kHuge);
    void* p = data_ ? ::mremap(data_, bytes_, bytes, MREMAP_MAYMOVE)
                    : ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    ::madvise(p, bytes, MADV_HUGEPAGE);  // advice only: without huge pages it still works
    data_ = p;
    bytes_ = bytes;
  }
  void* data_ = nullptr;
  std::size_t bytes_ = 0;
  std::size_t size_ = 0;
};

// Every event with t0 <= t < t1 (file order), at most max_events of them,
// from a reused batch (cache-sized) into the buffer.
void readRange(const std::string& path, const ReaderOptions& options, double t0, double t1,
               std::size_t max_events, EventBuffer& out) {
  auto reader = openEventSource(path, options);
  const bool everything = t0 == -std::numeric_limits<double>::infinity() &&
                          t1 == std::numeric_limits<double>::infinity();
  if (t0 != -std::numeric_limits<double>::infinity()) reader->seekTime(t0);
  // Events may come back in time by up to backwards_tolerance: read that far past t1.
  const double stop = t1 + options.backwards_tolerance;
  std::vector<Event> batch;
  while (out.size() < max_events && reader->next(batch, std::size_t(1) << 16)) {
    if (everything) {
      out.append(batch.data(), std::min(batch.size(), max_events - out.size()));
      continue;
    }
    for (const Event& e : batch) {
      if (e.t >= stop || out.size() >= max_events) return;
      if (e.t >= t0 && e.t < t1) out.push(e);
    }
  }
}

pyb::array readEvents(const pyb::object& path, std::optional<double> t0, std::optional<double> t1,
                      std::optional<std::size_t> max_events, const pyb::object& options) {
  const ReaderOptions o = readerOptions(options, "read_events(options)");
  const std::string p = existingPath(path);
  // An empty or reversed range is a mistake, not a request for no events.
  if ((t0 && std::isnan(*t0)) || (t1 && std::isnan(*t1)) || (t0 && t1 && !(*t0 < *t1)))
    throw pyb::value_error("read_events: need t0 < t1 [s], got t0=" + (t0 ? std::to_string(*t0) : "None") +
                           ", t1=" + (t1 ? std::to_string(*t1) : "None"));
  EventBuffer events;
  {
    pyb::gil_scoped_release nogil;
    readRange(p, o, t0.value_or(-std::numeric_limits<double>::infinity()),
              t1.value_or(std::numeric_limits<double>::infinity()),
              max_events.value_or(std::numeric_limits<std::size_t>::max()), events);
  }
  return events.release();
}

pyb::array readImu(const pyb::object& path, const pyb::object& options) {
  const ReaderOptions o = readerOptions(options, "read_imu(options)");
  const std::string p = existingPath(path);
  std::vector<ImuSample> imu;
  {
    pyb::gil_scoped_release nogil;
    imu = openEventSource(p, o)->readImu();
  }
  return adoptVector(std::move(imu), imuDtype());
}

std::vector<ImuSample> imuFromPython(const pyb::handle& imu) {
  std::vector<ImuSample> out;
  if (imu.is_none()) return out;
  auto t = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(imu["t"]);
  auto g = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(imu["gyro"]);
  auto a = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(imu["acc"]);
  if (!t || !g || !a || t.ndim() != 1 || g.ndim() != 2 || a.ndim() != 2 || g.shape(0) != t.shape(0) ||
      a.shape(0) != t.shape(0) || g.shape(1) != 3 || a.shape(1) != 3)
    throw pyb::value_error("imu: expected fields t (N,), gyro (N, 3), acc (N, 3)");
  out.resize(static_cast<std::size_t>(t.shape(0)));
  for (pyb::ssize_t i = 0; i < t.shape(0); ++i) {
    ImuSample& s = out[static_cast<std::size_t>(i)];
    s.t = t.at(i);
    s.gyro = Vec3(g.at(i, 0), g.at(i, 1), g.at(i, 2));
    s.accel = Vec3(a.at(i, 0), a.at(i, 1), a.at(i, 2));
  }
  return out;
}

void writeEvents(const pyb::object& path, const pyb::object& events, const std::string& format,
                 const pyb::object& imu, const std::string& chip, int width, int height,
                 const std::string& compression) {
  const std::string p = pathString(path);
  const std::vector<Event> ev = eventsFromPython(events);
  const std::vector<ImuSample> im = imuFromPython(imu);
  Aedat4Compression c = Aedat4Compression::Lz4;
  if (compression == "none") c = Aedat4Compression::None;
  else if (compression == "zstd") c = Aedat4Compression::Zstd;
  else if (compression != "lz4") throw pyb::value_error("compression '" + compression + "': expected none, lz4 or zstd");
  if (format != "text" && format != "aedat2" && format != "aedat31" && format != "aedat4")
    throw pyb::value_error("format '" + format + "': expected text, aedat2, aedat31 or aedat4");
  if (format == "text" && !im.empty())
    throw pyb::value_error("format 'text': the events file holds no IMU (write it beside, imu.txt)");
  pyb::gil_scoped_release nogil;
  if (format == "text") writeEventsText(p, ev);
  else if (format == "aedat2") writeAedat2(p, ev, im, chip);
  else if (format == "aedat31") writeAedat31(p, ev, im, chip);
  else writeAedat4(p, ev, im, width, height, c);
}

pyb::dict info(const pyb::object& path, const pyb::object& options) {
  const ReaderOptions o = readerOptions(options, "info(options)");
  const std::string p = existingPath(path);
  FileInfo fi;
  {
    pyb::gil_scoped_release nogil;
    fi = scanFile(p, o);
  }
  pyb::dict d;
  d["format"] = toString(fi.format);
  d["path"] = fi.path;
  d["width"] = fi.width;
  d["height"] = fi.height;
  d["events"] = fi.events;
  d["on_events"] = fi.on_events;
  d["t_first"] = fi.t_first;
  d["t_last"] = fi.t_last;
  d["t_min"] = fi.t_min;
  d["t_max"] = fi.t_max;
  d["imu_samples"] = fi.imu_samples;
  d["warnings"] = fi.warnings.total();
  d["warning_messages"] = fi.warnings.messages;
  d["notes"] = fi.notes;
  return d;
}

}  // namespace

void bindReaders(pyb::module_& m) {
  m.attr("EVENT_DTYPE") = eventDtype();
  m.attr("IMU_DTYPE") = imuDtype();
  m.def("read_events", &readEvents, pyb::arg("path"), pyb::kw_only(), pyb::arg("t0") = pyb::none(),
        pyb::arg("t1") = pyb::none(), pyb::arg("max_events") = pyb::none(), pyb::arg("options") = pyb::none(),
        R"(Events of a recording as a structured array of EVENT_DTYPE: t float64 [s],
x, y float32 [px, origin top-left, x right, y down], p bool (ON).

path: an RPG / UZH-FPV directory, an events text file, AEDAT 2.0 / 3.1 / 4.0,
a ROS bag or an HDF5 file (format from the magic bytes, docs/formats.md).
t0, t1: keep t0 <= t < t1 [s]; max_events: at most that many (file order).
options: the `input:` section of a run configuration as a dict, e.g.
{"width": 240, "height": 180, "time_scale": 1e-6, "topic_events": "/dvs/events"}.
The array owns the reader's buffer (no copy after reading). Errors: OSError
(unreadable or malformed file, naming it), ValueError (bad option).)");
  m.def("read_imu", &readImu, pyb::arg("path"), pyb::kw_only(), pyb::arg("options") = pyb::none(),
        R"(IMU samples of a recording as a structured array of IMU_DTYPE: t [s],
gyro (3,) [rad/s], acc (3,) [m/s^2], in the IMU's own frame (empty when
the recording has none). No copy after reading.)");
  m.def("write_events", &writeEvents, pyb::arg("path"), pyb::arg("events"), pyb::kw_only(),
        pyb::arg("format") = "text", pyb::arg("imu") = pyb::none(), pyb::arg("chip") = "DAVIS346",
        pyb::arg("width") = 346, pyb::arg("height") = 260, pyb::arg("compression") = "lz4",
        R"(Writes events (and IMU, binary formats) with the library's writers:
format "text" (`t x y p`, t with 9 decimals, pixels as integers), "aedat2" /
"aedat31" (chip names the sensor, e.g. DAVIS240 or DAVIS346), "aedat4"
(width x height, compression none / lz4 / zstd). Binary formats round times
to whole microseconds.)");
  m.def("info", &info, pyb::arg("path"), pyb::kw_only(), pyb::arg("options") = pyb::none(),
        "What `celc info` reports of a recording (one pass): format, sensor size, counts, times [s], warnings.");
}

}  // namespace celc::py
