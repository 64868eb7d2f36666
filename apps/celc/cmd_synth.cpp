// `celc synth SCENE.yaml -o DIR`: the rendering event simulator.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "celc/io/sequence_layout.hpp"
#include "celc/sim/render_sequence.hpp"
#include "commands.hpp"

namespace celc::app {

namespace {
struct SynthArgs {
  std::string scene;
  std::string out;
  int64_t seed = -1;
  double duration = -1.0;
  int threads = 0;
  bool force = false;
  bool quiet = false, verbose = false;
};

void runSynth(const SynthArgs& a) {
  configureLogging(a.quiet, a.verbose);
  namespace fs = std::filesystem;
  SynthConfig cfg = loadSynthConfig(a.scene);
  if (a.seed >= 0) cfg.seed = static_cast<uint64_t>(a.seed);
  if (a.duration > 0.0) cfg.duration = a.duration;
  if (a.threads > 0) cfg.events.threads = a.threads;
  const std::string err = cfg.validate();
  if (!err.empty()) throw std::invalid_argument(a.scene + ": " + err);

  std::error_code ec;
  if (fs::exists(a.out, ec)) {
    if (!fs::is_directory(a.out, ec))
      throw std::runtime_error(a.out + ": exists and is not a directory");
    if (!fs::is_empty(a.out, ec) && !a.force)
      throw std::runtime_error(a.out +
                               ": directory exists and is not empty (use --force to overwrite)");
  }
  spdlog::info("synth: {} -> {} ({} {}x{}, {} plane(s), {} s, seed {})", a.scene, a.out,
               cfg.camera_preset, cfg.camera.width, cfg.camera.height, cfg.planes.size(),
               cfg.duration, cfg.seed);
  auto last = std::chrono::steady_clock::now();
  const double duration = cfg.duration;
  const bool show = !a.quiet;
  const auto summary = writeSequence(cfg, a.out, [&](double t, int64_t n) {
    const auto now = std::chrono::steady_clock::now();
    if (show && (now - last > std::chrono::seconds(2) || t >= duration)) {
      spdlog::info("synth: {:.3f} / {:.3f} s simulated, {} events", t, duration, n);
      last = now;
    }
  });
  const auto& s = summary.stats;
  const double on_share = summary.events > 0 ? double(s.events_on) / summary.events : 0.0;
  spdlog::info(
      "synth: {} events ({:.0f} ev/s of sequence, ON share {:.3f}, noise {}, refractory-dropped "
      "{}), {} renders (step {:.1f}..{:.1f} us), {} IMU samples, {} poses; {:.2f} s wall "
      "({:.2f} M events/s)",
      summary.events, summary.events / summary.duration, on_share, s.events_noise,
      s.refractory_dropped, s.renders, s.min_step * 1e6, s.max_step * 1e6, summary.imu_samples,
      summary.poses, summary.wall_seconds,
      summary.wall_seconds > 0 ? summary.events / summary.wall_seconds * 1e-6 : 0.0);
}

// "events.txt, labels.txt, ...": the files `celc synth` writes.
std::string synthFileList() {
  std::string list;
  for (const char* name : simulatedSequenceFiles()) list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}
}  // namespace

void registerSynth(CLI::App& app) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* cmd = app.add_subcommand(
      "synth",
      "Rendering event simulator: textured planes seen by a moving DAVIS-like camera; writes an\n"
      "RPG-style sequence directory (" +
          synthFileList() + ").\nSchema: docs/simulation.md, config/scenes/.");
  cmd->add_option("scene", args->scene, "SCENE.yaml describing camera, planes, motion, events, IMU")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->out, "output sequence directory")->required();
  cmd->add_option("--seed", args->seed,
                  "random seed (overrides `seed`; thresholds, noise, textures)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--duration", args->duration, "simulated duration [s] (overrides `duration`)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", args->threads,
                  "render threads (overrides events.threads; default 2)")
      ->check(CLI::Range(1, 64));
  cmd->add_flag("--force", args->force, "write into an existing non-empty directory");
  cmd->add_flag("-q,--quiet", args->quiet, "warnings and errors only");
  cmd->add_flag("-v,--verbose", args->verbose, "debug output");
  cmd->callback([args] { runSynth(*args); });
}

}  // namespace celc::app
