// celc: event-camera linear velocity from the Continuous Event-Line Constraint.
#include <glog/logging.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <iostream>

#include "celc/core/memory.hpp"
#include "commands.hpp"

namespace celc::app {
void configureLogging(bool quiet, bool verbose) {
  spdlog::set_level(quiet ? spdlog::level::warn
                          : (verbose ? spdlog::level::debug : spdlog::level::info));
}
}  // namespace celc::app

int main(int argc, char** argv) {
  celc::tuneHeapForLargeBuffers();
  // Ceres logs through glog: its warnings and its "evaluation failed" errors
  // are not for users (a refinement that fails is reported as a per-window
  // status with Ceres' message); only fatal errors are printed.
  FLAGS_minloglevel = google::GLOG_FATAL;
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  auto logger = spdlog::stderr_color_mt("celc");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%H:%M:%S] %^%l%$ %v");

  CLI::App app{
      "celc " CELC_VERSION
      ": linear velocity of an event camera from the Continuous Event-Line Constraint\n"
      "(Peng, Xu, Yang, Kneip, BMVC 2021). Units: seconds, pixels, metres, radians."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("celc ") + CELC_VERSION + " (git " + celc::app::gitRevision() + ")");
  // Subcommands, in the order `celc --help` lists them.
  celc::app::registerRun(app);
  celc::app::registerBatch(app);
  celc::app::registerTable(app);
  celc::app::registerSimulate(app);
  celc::app::registerSolve(app);
  celc::app::registerInfo(app);
  celc::app::registerCluster(app);
  celc::app::registerSynth(app);
  celc::app::registerConfig(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // `celc runn x`: CLI11 says only that a subcommand is required; name the word it did not know.
    if (argc > 1 && argv[1][0] != '-') {
      std::string known;
      bool is_known = false;
      for (const CLI::App* sub : app.get_subcommands({})) {
        known += (known.empty() ? "" : ", ") + sub->get_name();
        is_known = is_known || sub->get_name() == argv[1];
      }
      if (!is_known) {
        std::cerr << "celc: error: unknown subcommand '" << argv[1] << "' (the subcommands: " << known << ")\n";
        return 2;
      }
    }
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "celc: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
