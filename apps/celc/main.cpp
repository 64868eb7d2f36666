// celc: event-camera linear velocity from the Continuous Event-Line Constraint.
#include <glog/logging.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>

#include "celc/core/memory.hpp"
#include "celc/io/event_reader.hpp"
#include "commands.hpp"

namespace celc::app {
namespace {
/// `text` with every line made printable ASCII (control bytes and bytes >=
/// 0x7F as \xNN, as the readers quote file contents): a file name holding an
/// escape sequence never reaches the terminal raw. Line breaks are kept.
std::string printableLines(const std::string& text) {
  std::string out;
  std::size_t p = 0;
  while (p < text.size()) {
    const std::size_t e = std::min(text.find('\n', p), text.size());
    out += celc::detail::printable(text.substr(p, e - p), e - p);
    if (e < text.size()) out += '\n';
    p = e + 1;
  }
  return out;
}
}  // namespace

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
        std::cerr << "celc: error: unknown subcommand '" << celc::app::printableLines(argv[1])
                  << "' (the subcommands: " << known << ")\n";
        return 2;
      }
    }
    std::ostringstream err;  // CLI11's messages quote the arguments (a path): escaped like every message
    const int status = app.exit(e, std::cout, err);
    std::cerr << celc::app::printableLines(err.str());
    return status;
  } catch (const std::exception& e) {
    std::cerr << "celc: error: " << celc::app::printableLines(e.what()) << "\n";
    return 1;
  }
  return 0;
}
