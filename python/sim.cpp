// celc.simulate_window (the paper's line scene, sim/line_scene.hpp) and
// celc.synth (the rendering simulator, sim/render_sequence.hpp).
#include <pybind11/stl.h>

#include <filesystem>
#include <optional>
#include <random>

#include "celc/sim/line_scene.hpp"
#include "celc/sim/render_sequence.hpp"
#include "common.hpp"

namespace celc::py {
namespace {

pyb::array_t<double> vec3(const Vec3& v) { return pyb::array_t<double>(3, v.data()); }

pyb::dict simulateWindow(std::uint64_t seed, const pyb::kwargs& scene) {
  LineSceneOptions o;
  applyDict(scene, "simulate_window", [&](FieldVisitor& v) { describe(v, o); });
  if (const std::string err = o.validate(); !err.empty()) throw ConfigError("simulate_window: " + err);
  LineSceneTrial trial;
  {
    pyb::gil_scoped_release nogil;
    std::mt19937_64 rng(seed);
    trial = generateLineScene(o, rng);
  }
  pyb::dict d;
  const std::vector<int> labels = trial.labels;
  d["events"] = adoptVector(std::move(trial.pixel_events), eventDtype());
  d["labels"] = pyb::array_t<int>(static_cast<pyb::ssize_t>(labels.size()), labels.data());
  d["direction"] = vec3(trial.true_direction);
  d["velocity"] = vec3(o.velocity);
  d["omega"] = vec3(trial.given_motion.meanOmega(0.0, o.duration));
  d["true_omega"] = vec3(trial.true_motion.meanOmega(0.0, o.duration));
  pyb::dict cam;
  cam["width"] = o.camera.width;
  cam["height"] = o.camera.height;
  cam["fx"] = o.camera.fx;
  cam["fy"] = o.camera.fy;
  cam["cx"] = o.camera.cx;
  cam["cy"] = o.camera.cy;
  d["camera"] = cam;
  pyb::array_t<double> seg({static_cast<pyb::ssize_t>(trial.segments.size()), pyb::ssize_t(2), pyb::ssize_t(3)});
  for (std::size_t i = 0; i < trial.segments.size(); ++i)
    for (int e = 0; e < 2; ++e)
      for (int k = 0; k < 3; ++k)
        seg.mutable_at(static_cast<pyb::ssize_t>(i), e, k) = trial.segments[i][static_cast<std::size_t>(e)](k);
  d["segments"] = seg;
  return d;
}

pyb::dict synth(const pyb::object& scene, const pyb::object& out_dir, std::optional<std::uint64_t> seed,
                std::optional<double> duration, std::optional<int> threads, bool force) {
  SynthConfig cfg;
  const bool is_text = pyb::isinstance<pyb::str>(scene) && scene.cast<std::string>().find('\n') != std::string::npos;
  if (is_text) cfg = parseSynthConfig(scene.cast<std::string>(), "synth(scene)");
  else cfg = loadSynthConfig(existingPath(scene));
  if (seed) cfg.seed = *seed;
  if (duration) cfg.duration = *duration;
  if (threads) cfg.events.threads = *threads;
  if (const std::string err = cfg.validate(); !err.empty()) throw ConfigError("synth: " + err);
  const std::string out = pathString(out_dir);
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec)) throw pyb::value_error(out + ": exists and is not a directory");
    if (!fs::is_empty(out, ec) && !force)
      throw pyb::value_error(out + ": directory exists and is not empty (force=True to overwrite)");
  }
  SynthSummary s;
  {
    pyb::gil_scoped_release nogil;
    s = writeSequence(cfg, out);
  }
  pyb::dict d;
  d["dir"] = out;
  d["events"] = s.events;
  d["events_on"] = s.stats.events_on;
  d["imu_samples"] = s.imu_samples;
  d["poses"] = s.poses;
  d["duration"] = s.duration;
  d["wall_seconds"] = s.wall_seconds;
  return d;
}

}  // namespace

void bindSim(pyb::module_& m) {
  m.def("simulate_window", &simulateWindow, pyb::kw_only(), pyb::arg("seed") = 1,
        R"(One window of the paper's simulation (Sec. 5.1; `celc simulate`'s scene):
random 3D segments seen by a camera with a constant twist, events on them
with Gaussian pixel noise. Keyword arguments are keys of the `scene:`
schema (`celc config --show simulate`), e.g. n_lines=5, events_per_line=200,
duration=0.5 [s], velocity=[1, 2, 0] [m/s], omega=[0, 0, 2] [rad/s],
event_noise_px=2, camera={"fx": 320}. Deterministic for a seed.

Returns {"events" (EVENT_DTYPE, pixels), "labels" (segment per event, -1 =
outlier), "direction" (true unit v, camera frame), "velocity", "omega" (the
angular velocity given to the solvers, with omega_noise; the mean rate under
gyro_integrated), "true_omega", "camera" (dict for solve(calib=...)),
"segments" (n, 2, 3) [m]}.)");
  m.def("synth", &synth, pyb::arg("scene"), pyb::arg("out_dir"), pyb::kw_only(), pyb::arg("seed") = pyb::none(),
        pyb::arg("duration") = pyb::none(), pyb::arg("threads") = pyb::none(), pyb::arg("force") = false,
        R"(`celc synth`: renders the scene (a SCENE.yaml path, or YAML text holding
a newline; docs/simulation.md) into the sequence directory out_dir (events.txt,
imu.txt, groundtruth.txt, calib.yaml, ...), which celc.run reads as it is.
seed, duration [s], threads override the scene's. Returns a summary dict
(events, events_on, imu_samples, poses, duration [s], wall_seconds).)");
}

}  // namespace celc::py
