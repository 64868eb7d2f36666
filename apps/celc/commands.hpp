#pragma once
/// \file commands.hpp
/// One function per subcommand: each adds its CLI11 subcommand to the app and
/// binds a callback. Subcommands parse options, call the library and write
/// files; they hold no algorithms.
#include <CLI/CLI.hpp>

namespace celc::app {

void registerSimulate(CLI::App& app);
void registerSolve(CLI::App& app);
void registerRun(CLI::App& app);
void registerBatch(CLI::App& app);
void registerTable(CLI::App& app);
/// `celc info FILE|DIR` (cmd_info.cpp).
void registerInfo(CLI::App& app);
/// `celc cluster EVENTS`: clustering of an event file's windows (cmd_cluster.cpp).
void registerCluster(CLI::App& app);
/// `celc synth SCENE.yaml -o DIR`: the rendering event simulator (cmd_synth.cpp).
void registerSynth(CLI::App& app);
/// `celc config`: defaults and keys of the configuration schema (cmd_config.cpp).
void registerConfig(CLI::App& app);

/// The git revision the executable was built from (`git describe --always
/// --dirty`; "unknown" outside a checkout), generated at build time.
const char* gitRevision();

/// Sets the spdlog level from --quiet / --verbose flags shared by all subcommands.
void configureLogging(bool quiet, bool verbose);

}  // namespace celc::app
