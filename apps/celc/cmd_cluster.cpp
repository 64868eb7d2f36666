// celc cluster EVENTS: clusters windows of an event file and reports, per
// window, what came out; with --dump DIR also a PNG and a PLY per window.
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "celc/cluster/cluster.hpp"
#include "celc/core/yaml.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/cluster/dump.hpp"
#include "celc/io/event_reader.hpp"
#include "celc/io/window_source.hpp"
#include "commands.hpp"

namespace celc::app {
namespace {

struct ClusterArgs {
  std::string events;
  size_t window_events = 30000;
  std::string dump;
  std::string method = "grid";
  double c = 0.0;
  bool merge_polarity = false;
  int threads = 2;
  size_t max_windows = 0;
  int width = 0, height = 0;
  double smoothness_deg = ClusterOptions{}.smoothness_deg;
  double curvature = ClusterOptions{}.curvature_threshold;
  int min_cluster_size = ClusterOptions{}.min_cluster_size;
  double max_plane_rms_px = ClusterOptions{}.max_plane_rms_px;
  std::string config;
  bool quiet = false, verbose = false;
};

void run(const ClusterArgs& a, const CLI::App& cmd) {
  configureLogging(a.quiet, a.verbose);
  ClusterOptions opt;
  LineFitOptions lines;
  if (!a.config.empty()) {  // the config file first (its cluster: and lines:), then the options given
    const RunConfig config = loadRunConfig(a.config);
    opt = config.cluster;
    lines = config.observations.lines;
  }
  auto given = [&](const char* name) { return a.config.empty() || cmd.count(name) > 0; };
  if (given("--method")) opt.method = parseClusterMethod(a.method);
  if (given("--c-px-per-s")) opt.c_px_per_s = a.c;
  if (cmd.count("--merge-polarity") > 0) opt.separate_polarity = false;
  if (given("--threads")) opt.threads = a.threads;
  if (given("--smoothness-deg")) opt.smoothness_deg = a.smoothness_deg;
  if (given("--curvature")) opt.curvature_threshold = a.curvature;
  if (given("--min-cluster-size")) opt.min_cluster_size = a.min_cluster_size;
  if (given("--max-plane-rms")) opt.max_plane_rms_px = a.max_plane_rms_px;
  if (const std::string err = opt.validate(); !err.empty())
    throw std::runtime_error("invalid clustering options: " + err);
  if (const std::string why = clusterMethodProblem(opt.method); !why.empty()) throw std::runtime_error(why);
  // Any format the io module reads (text, AEDAT 2.0 / 3.1 / 4.0), window by window.
  ReaderOptions ro;
  ro.width = a.width;
  ro.height = a.height;
  const auto reader = openEventSource(a.events, ro);
  WindowOptions wo;
  wo.events_per_window = a.window_events;
  WindowSource source(*reader, wo);
  if (!a.dump.empty()) std::filesystem::create_directories(a.dump);
  std::cout << "window,t_start,t_end,n_events,status,c_px_per_s,n_clusters,n_clustered,runtime_ms,smoothness_deg,"
               "left_invalid,left_no_region,left_small_region,left_failed_checks,left_off_planes\n";
  EventWindow win;
  for (size_t window = 0; source.next(win); ++window) {
    if (a.max_windows > 0 && window >= a.max_windows) break;
    const std::vector<Event>& ev = win.events;
    const ClusterResult r = clusterEvents(ev, opt);
    char row[256];
    const ClusterLosses& left = r.left_out;
    std::snprintf(row, sizeof row, "%zu,%.6f,%.6f,%zu,%s,%.1f,%zu,%d,%.1f,%.2f,%d,%d,%d,%d,%d", window, ev.front().t,
                  ev.back().t, ev.size(), toString(r.status).c_str(), r.c_px_per_s, r.clusters.size(),
                  r.n_clustered, r.ms_total, r.smoothness_deg, left.invalid, left.no_region, left.small_region,
                  left.failed_checks, left.off_planes);
    std::cout << row << "\n";
    if (!a.dump.empty()) {
      char name[64];
      std::snprintf(name, sizeof name, "window_%05zu", window);
      const std::string base = (std::filesystem::path(a.dump) / name).string();
      ClusterDumpOptions d;
      d.width = a.width;
      d.height = a.height;
      d.title = name;
      d.lines = lines;
      writeClusterPng(base + ".png", ev, r, d);
      writeClusterPly(base + ".ply", ev, r);
      spdlog::debug("wrote {}.png / .ply", base);
    }
  }
}

}  // namespace

void registerCluster(CLI::App& app) {
  auto args = std::make_shared<ClusterArgs>();
  CLI::App* cmd = app.add_subcommand(
      "cluster",
      "Space-time clustering of an event file's windows into line clusters; prints one CSV row "
      "per window (window,t_start,t_end,n_events,status,c_px_per_s,n_clusters,n_clustered,runtime_ms,smoothness_deg,"
      "left_invalid,left_no_region,left_small_region,left_failed_checks,left_off_planes: where the unclustered "
      "events went, docs/clustering.md)");
  cmd->add_option("EVENTS", args->events, "an event file or recording in any format celc run reads (text 't x y p', AEDAT, bag, HDF5)")
      ->required();
  cmd->add_option("--window-events", args->window_events, "events per window [events]")
      ->capture_default_str()
      ->check(CLI::Range(size_t{1}, size_t{100000000}));
  cmd->add_option("--dump", args->dump, "directory for window_NNNNN.png (x-y and x-t views) and .ply");
  // Help of the options that stand for a key: from the schema.
  ClusterOptions cluster_defaults;
  LineFitOptions line_defaults;
  const Describe schema = [&](FieldVisitor& v) { describeClustering(v, cluster_defaults, line_defaults); };
  cmd->add_option("--method", args->method, fieldHelp(schema, "cluster.method"));
  cmd->add_option("--c-px-per-s", args->c, fieldHelp(schema, "cluster.c_px_per_s"));
  cmd->add_flag("--merge-polarity", args->merge_polarity, "cluster ON and OFF events together");
  cmd->add_option("--threads", args->threads, "worker threads")->capture_default_str();
  cmd->add_option("--max-windows", args->max_windows, "stop after this many windows (0 = all)")
      ->capture_default_str();
  cmd->add_option("--width", args->width, "sensor width for the PNG [px] (0 = from the events)");
  cmd->add_option("--height", args->height, "sensor height for the PNG [px] (0 = from the events)");
  cmd->add_option("--smoothness-deg", args->smoothness_deg, fieldHelp(schema, "cluster.smoothness_deg"));
  cmd->add_option("--curvature", args->curvature, fieldHelp(schema, "cluster.curvature_threshold"));
  cmd->add_option("--min-cluster-size", args->min_cluster_size, fieldHelp(schema, "cluster.min_cluster_size"));
  cmd->add_option("--max-plane-rms", args->max_plane_rms_px, fieldHelp(schema, "cluster.max_plane_rms_px"));
  cmd->add_option("-c,--config", args->config,
                  "YAML with 'cluster:' and 'lines:' sections (config/cluster.yaml); command-line "
                  "options given explicitly override it");
  cmd->add_flag("-q,--quiet", args->quiet, "warnings and errors only");
  cmd->add_flag("-v,--verbose", args->verbose, "debug output");
  cmd->callback([args, cmd] { run(*args, *cmd); });
}

}  // namespace celc::app
