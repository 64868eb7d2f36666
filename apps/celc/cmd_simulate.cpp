// `celc simulate`: the paper's simulation study (CSV per sweep, plots, table).
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>

#include "celc/config/config.hpp"
#include "celc/core/yaml.hpp"
#include "celc/io/labelled_events.hpp"
#include "celc/pipeline/peer_study.hpp"
#include "celc/pipeline/simulation_study.hpp"
#include "commands.hpp"
#include "plots.hpp"
#include "run_common.hpp"
#include "progress.hpp"

namespace fs = std::filesystem;

namespace celc::app {
namespace {

struct SimulateArgs {
  std::string sweep = "all";
  std::string study = "paper";
  std::string config;
  std::string outdir = "celc_simulate";
  std::string methods;
  int trials = 0;  // 0 = from the configuration
  long long seed = -1;
  int threads = 0;
  bool force = false, no_plots = false, quiet = false, verbose = false;
  std::vector<std::string> sets;  ///< --set key.path=value
};

std::string fmtCell(double x) { return std::isfinite(x) ? fmt::format("{:.4f}", x) : "-"; }

// The default-setting table (mean +- std of eps and phi per method).
void printDefaultTable(const std::vector<SweepCell>& cells) {
  std::cout << "\nDefault setting (paper Sec. 5.1): mean +- std over the trials with status ok\n\n"
            << "| method | ok / trials | eps (unit-vector distance) | phi [rad] | median phi [rad] | sign right | median time [us] |\n"
            << "|---|---|---|---|---|---|---|\n";
  for (const auto& c : cells)
    std::cout << fmt::format("| {} | {} / {} | {} +- {} | {} +- {} | {} | {} | {:.0f} |\n",
                             toString(c.method), c.n_ok, c.trials, fmtCell(c.eps_mean),
                             fmtCell(c.eps_std), fmtCell(c.phi_mean), fmtCell(c.phi_std),
                             fmtCell(c.phi_median), c.sign_right, c.time_median_us);
}

// A sweep as a compact table: rows levels, columns methods, mean phi [rad].
void printSweepTable(const Sweep& sweep, const std::vector<SweepCell>& cells,
                     const std::vector<Method>& methods) {
  std::cout << "\nSweep " << sweep.name << ": mean phi [rad] (ok trials)\n\n| " << sweep.parameter;
  for (Method m : methods) std::cout << " | " << toString(m);
  std::cout << " |\n|---";
  for (size_t i = 0; i < methods.size(); ++i) std::cout << "|---";
  std::cout << "|\n";
  for (size_t i = 0; i < cells.size(); i += methods.size()) {
    std::cout << "| " << fmt::format("{:g}", cells[i].level);
    for (size_t m = 0; m < methods.size(); ++m) {
      const auto& c = cells[i + m];
      std::cout << " | " << fmtCell(c.phi_mean) << " (" << c.n_ok << ")";
    }
    std::cout << " |\n";
  }
}

// A sweep's medians: rows levels, columns methods, median phi [deg] and the
// median solver time [ms] of the ok trials.
void printMedianTable(const Sweep& sweep, const std::vector<SweepCell>& cells, const std::vector<Method>& methods) {
  std::cout << "\nSweep " << sweep.name << ": median phi [deg] / median time [ms] (ok trials)\n\n| "
            << sweep.parameter;
  for (Method m : methods) std::cout << " | " << toString(m);
  std::cout << " |\n|---";
  for (size_t i = 0; i < methods.size(); ++i) std::cout << "|---";
  std::cout << "|\n";
  for (size_t i = 0; i < cells.size(); i += methods.size()) {
    std::cout << "| " << fmt::format("{:g}", cells[i].level);
    for (size_t m = 0; m < methods.size(); ++m) {
      const auto& c = cells[i + m];
      std::cout << " | " << fmt::format("{:.3f}", c.phi_median * 180.0 / M_PI) << " / "
                << fmt::format("{:.1f}", c.time_median_us * 1e-3);
    }
    std::cout << " |\n";
  }
}

// The uncertainty study: per setting and method the share of ok trials with
// phi <= 2 sigma_deg (target 0.85-0.99), the median sigma, and how many ok
// trials claim sigma < 10 deg. OUTDIR/sigma.csv holds the same;
// OUTDIR/sigma_trials.csv one row per ok trial and method (phi [rad],
// sigma_deg, the window's D translation_px, sigma_rule), for
// scripts/sigma_bins.py.
void runSigmaStudy(const SimulateArgs& a, const SimulateConfig& cfg, const fs::path& out) {
  std::string csv = "sweep,level,method,trials,n_ok,covered_2sigma,share_2sigma,sigma_median_deg,ok_sigma_below_10deg\n";
  std::string trials_csv = "sweep,level,method,status,phi,sigma_deg,translation_px,sigma_rule\n";
  std::cout << "\nUncertainty calibration: share of ok trials with phi <= 2 sigma_deg (ok trials; median "
               "sigma_deg; ok trials with sigma_deg < 10)\n\n| setting | level";
  for (Method m : cfg.methods) std::cout << " | " << toString(m);
  std::cout << " |\n|---|---";
  for (size_t i = 0; i < cfg.methods.size(); ++i) std::cout << "|---";
  std::cout << "|\n";
  for (const Sweep& sweep : sigmaSweeps()) {
    Progress progress("simulate sigma " + sweep.name, a.quiet);
    const auto cells = runSweep(sweep, cfg, a.threads, [&](int done, int total) { progress.update(done, total); });
    for (size_t i = 0; i < cells.size(); i += cfg.methods.size()) {
      std::cout << "| " << sweep.name << " | " << fmt::format("{:g}", cells[i].level);
      for (size_t m = 0; m < cfg.methods.size(); ++m) {
        const SweepCell& c = cells[i + m];
        const double share = c.n_ok > 0 ? double(c.covered_2sigma) / c.n_ok : NAN;
        std::cout << " | " << fmtCell(share) << " (" << c.n_ok << "; " << fmt::format("{:.2g}", c.sigma_median_deg)
                  << "; " << c.confident_10deg << ")";
        csv += fmt::format("{},{},{},{},{},{},{},{},{}\n", c.sweep, c.level, toString(c.method), c.trials, c.n_ok,
                           c.covered_2sigma, share, c.sigma_median_deg, c.confident_10deg);
        for (const SweepCell::SigmaSample& s : c.samples)
          trials_csv += fmt::format("{},{},{},ok,{:.9g},{:.6g},{},{}\n", c.sweep, c.level, toString(c.method), s.phi,
                                    s.sigma_deg,
                                    std::isfinite(s.translation_px) ? fmt::format("{:.2f}", s.translation_px) : "",
                                    s.sigma_rule);
      }
      std::cout << " |\n";
    }
  }
  writeFileAtomically((out / "sigma.csv").string(), csv);
  writeFileAtomically((out / "sigma_trials.csv").string(), trials_csv);
  std::cout << std::flush;
}

// Runs a plot script on OUTDIR; a failure is a warning.
void plotSimulation(const std::string& name, const fs::path& out) {
  if (const std::string error = runPlotScript(name, {out.string()}); !error.empty())
    spdlog::warn("no plots of {}: {}", out.string(), error);
  else
    spdlog::info("plots written to {}/*.png", out.string());
}

// The peer study: OUTDIR/peers.csv, a Markdown table on stdout, plots.
void runPeers(const SimulateArgs& a, const SimulateConfig& cfg) {
  PeerStudyConfig pc;
  pc.solver = cfg.solver;
  // Every window of the peer scene moves; the parallax test (meant for real
  // data) rejects whole windows once 10% uniform outliers inflate its robust
  // scales, for every method alike. Off here, so the outlier cells are solved.
  pc.solver.check_parallax = false;
  pc.methods = cfg.methods;
  pc.trials = a.trials > 0 ? a.trials : 200;
  pc.seed = cfg.seed;
  if (const std::string err = pc.validate(); !err.empty())
    throw std::runtime_error("peer study: " + err);
  const fs::path out(a.outdir);
  if (fs::exists(out / "peers.csv") && !a.force)
    throw std::runtime_error(out.string() + ": holds results of an earlier run (use --force to overwrite)");
  fs::create_directories(out);
  const auto cells = peerStudyCells();
  spdlog::info("simulate --study peers: {} cells, {} trials per cell, seed {}, output {}",
               cells.size(), pc.trials, pc.seed, out.string());
  Progress progress("simulate peers", a.quiet);
  const auto rows = runPeerStudy(cells, pc, a.threads,
                                 [&](int done, int total) { progress.update(done, total); });
  std::string csv = peerCsvHeader() + "\n";
  for (const auto& r : rows) csv += peerCsvRow(r, pc.scene) + "\n";
  writeFileAtomically((out / "peers.csv").string(), csv);

  const size_t nm = pc.methods.size();
  std::cout << "\nPeer study: median sign-agnostic phi [deg] / RMS over CRLB / median time [us]"
               " (ok trials of " << pc.trials << ")\n\n| cell | V | sigma | w err | lines | events | outl. | CRLB [deg]";
  for (Method m : pc.methods) std::cout << " | " << toString(m);
  std::cout << " |\n|---|---|---|---|---|---|---|---";
  for (size_t i = 0; i < nm; ++i) std::cout << "|---";
  std::cout << "|\n";
  for (size_t i = 0; i < rows.size(); i += nm) {
    const PeerCell& c = rows[i].cell;
    std::cout << fmt::format("| {} | {:g} | {:g} | {:g} | {} | {} | {:g} | {}", c.groups, c.speed,
                             c.sigma_px, c.omega_error_deg_s, c.lines, c.events_per_line,
                             c.outliers, fmtCell(rows[i].crlb_rms_deg));
    for (size_t m = 0; m < nm; ++m) {
      const auto& r = rows[i + m];
      std::cout << fmt::format(" | {} / {} / {:.0f}", fmtCell(r.phi_median_agn_deg),
                               std::isfinite(r.ratio) ? fmt::format("{:.2f}", r.ratio) : "-",
                               r.time_median_us);
    }
    std::cout << " |\n";
  }
  std::cout << std::flush;
  if (automaticPlots(a.no_plots)) plotSimulation("plot_peers.py", out);
}

void runSimulate(const SimulateArgs& a) {
  configureLogging(a.quiet, a.verbose);
  checkThreads(a.threads);
  SimulateConfig cfg;
  if (!a.config.empty()) cfg = loadSimulateConfig(a.config);
  for (const std::string& assignment : a.sets) applySimulateSetting(assignment, cfg);
  if (a.trials > 0) cfg.trials = a.trials;
  if (a.seed >= 0) cfg.seed = static_cast<std::uint64_t>(a.seed);
  if (!a.methods.empty()) cfg.methods = parseMethodList(a.methods);
  if (a.study != "paper" && a.study != "peers" && a.study != "sigma")
    throw std::invalid_argument("unknown study '" + a.study + "' (expected paper, peers or sigma)");
  if (a.study == "peers" || a.sweep == "peers") {
    runPeers(a, cfg);
    return;
  }

  if (a.study == "sigma") {
    const fs::path out(a.outdir);
    if (fs::exists(out / "config.yaml") && !a.force)
      throw std::runtime_error(out.string() + ": holds results of an earlier run (use --force to overwrite)");
    fs::create_directories(out);
    writeFileAtomically((out / "config.yaml").string(), toYaml(cfg));
    runSigmaStudy(a, cfg, out);
    return;
  }

  std::vector<const Sweep*> sweeps{&findSweep("default")};
  if (a.sweep == "all") {
    for (const auto& s : paperSweeps())
      if (s.name != "default") sweeps.push_back(&s);
  } else if (a.sweep != "default") {
    sweeps.push_back(&findSweep(a.sweep));
  }

  const fs::path out(a.outdir);
  if (fs::exists(out / "config.yaml") && !a.force)
    throw std::runtime_error(out.string() + ": holds results of an earlier run (use --force to overwrite)");
  fs::create_directories(out);
  writeFileAtomically((out / "config.yaml").string(), toYaml(cfg));
  spdlog::info("simulate: {} sweep(s), {} trials per level, seed {}, output {}", sweeps.size(),
               cfg.trials, cfg.seed, out.string());

  for (const Sweep* sweep : sweeps) {
    Progress progress("simulate " + sweep->name, a.quiet);
    const auto cells = runSweep(*sweep, cfg, a.threads,
                                [&](int done, int total) { progress.update(done, total); });
    std::string csv = sweepCsvHeader() + "\n";
    for (const auto& c : cells) csv += sweepCsvRow(c) + "\n";
    writeFileAtomically((out / (sweep->name + ".csv")).string(), csv);
    if (sweep->name == "default") printDefaultTable(cells);
    else printSweepTable(*sweep, cells, cfg.methods);
    if (sweep->name == "acceleration") printMedianTable(*sweep, cells, cfg.methods);
  }
  std::cout << std::flush;

  if (!automaticPlots(a.no_plots) || sweeps.size() < 2) return;
  plotSimulation("plot_simulation.py", out);
}

}  // namespace

void registerSimulate(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  auto* cmd = app.add_subcommand(
      "simulate",
      "The paper's simulation study (Sec. 5.1): random 3D lines, events with pixel noise, per "
      "level of a swept parameter the mean/std of eps = |v_gt - v| and phi = angle(v_gt, v) "
      "[rad] per method. Writes OUTDIR/<sweep>.csv, OUTDIR/config.yaml and plots "
      "OUTDIR/<sweep>.png; prints the tables.");
  cmd->add_option("--sweep", a->sweep,
                  "all, default, event_noise, line_noise, omega_noise, speed, interval, lines "
                  "(the paper's study), acceleration (rho = |a| Z / (2 V^2) from 0 to 30; not in all; "
                  "also prints median phi [deg] and time [ms]), or peers (= --study peers)")
      ->capture_default_str();
  cmd->add_option("--study", a->study,
                  "paper: the paper's sweeps; sigma: the calibration of sigma_deg (share of ok trials with "
                  "phi <= 2 sigma per setting and method, OUTDIR/sigma.csv); peers: npt and CELC on the peers' scene (640x480, "
                  "f 320 px, T 0.5 s) beside the Cramer-Rao bound, OUTDIR/peers.csv and "
                  "peers_*.png; --trials defaults to 200 there")
      ->capture_default_str();
  cmd->add_option("-c,--config", a->config, "YAML configuration (see config/simulate.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--outdir", a->outdir, "output folder")->capture_default_str();
  SimulateConfig defaults;  // help of the options that stand for a key: from the schema
  const Describe schema = [&](FieldVisitor& v) { describe(v, defaults); };
  cmd->add_option("--trials", a->trials, fieldHelp(schema, "study.trials"))->check(CLI::PositiveNumber);
  cmd->add_option("--seed", a->seed, fieldHelp(schema, "study.seed"))->check(CLI::NonNegativeNumber);
  cmd->add_option("--set", a->sets,
                  "override any configuration key, e.g. --set scene.n_lines=8 (repeatable; YAML values; "
                  "`celc config --show simulate --keys` lists every key)");
  cmd->add_option("--threads", a->threads, "worker threads (0 = all cores, at most 1024)")
      ->capture_default_str();
  cmd->add_option("--methods", a->methods,
                  "comma-separated celc,celc_opt,celc_ml,ce3lc,npt,celc_acc (or all): " + fieldHelp(schema, "study.methods"));
  cmd->add_flag("--force", a->force, "overwrite the results in OUTDIR");
  cmd->add_flag("--no-plots", a->no_plots, "skip the PNG plots");
  cmd->add_flag("-q,--quiet", a->quiet, "only warnings and errors on stderr");
  cmd->add_flag("-v,--verbose", a->verbose, "debug logging");
  cmd->callback([a]() { runSimulate(*a); });
}

}  // namespace celc::app
