// `celc config`: the configuration schema. Prints the default configuration
// of a subcommand, lists every key, or rewrites the shipped config/*.yaml.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "celc/config/config.hpp"
#include "celc/core/yaml.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/shipped_configs.hpp"
#include "commands.hpp"

namespace celc::app {
namespace {

struct ConfigArgs {
  std::string show = "run";
  bool keys = false;
  std::string write_defaults;
  std::string write_reference;
};

void writeFiles(const std::vector<ShippedConfig>& files, const std::string& dir) {
  for (const ShippedConfig& f : files) {
    const std::string path = (std::filesystem::path(dir) / f.file).string();
    std::ofstream out(path, std::ios::binary);
    if (!(out << f.text)) throw std::runtime_error(path + ": cannot write");
    std::cerr << "wrote " << path << "\n";
  }
}

void run(const ConfigArgs& a) {
  if (!a.write_defaults.empty() || !a.write_reference.empty()) {
    if (!a.write_defaults.empty()) writeFiles(shippedConfigs(), a.write_defaults);
    if (!a.write_reference.empty()) writeFiles(shippedReferences(), a.write_reference);
    return;
  }
  RunConfig run_config;
  SimulateConfig simulate_config;
  const Describe describe = a.show == "run" ? Describe([&](FieldVisitor& v) { celc::describe(v, run_config); })
                                            : Describe([&](FieldVisitor& v) { celc::describe(v, simulate_config); });
  if (!a.keys) {
    std::cout << writeYaml(describe);
    return;
  }
  for (const FieldEntry& f : listFields(describe))
    std::cout << f.key << " = " << f.value << (f.unit.empty() ? "" : "  [" + f.unit + "]") << "  " << f.doc
              << "\n";
}

}  // namespace

void registerConfig(CLI::App& app) {
  auto a = std::make_shared<ConfigArgs>();
  auto* cmd = app.add_subcommand(
      "config",
      "The configuration schema: prints the defaults of `celc run` (or `simulate`) as YAML with "
      "units and docs, a start for -c files.");
  cmd->add_option("--show", a->show, "which configuration: run (also batch) or simulate")
      ->check(CLI::IsMember({"run", "simulate"}))
      ->capture_default_str();
  cmd->add_flag("--keys", a->keys, "one line per key: dotted key = default [unit] doc");
  cmd->add_option("--write-defaults", a->write_defaults,
                  "rewrite run.yaml, simulate.yaml and cluster.yaml in this folder (config/)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--write-reference", a->write_reference,
                  "write the key reference pages run.md and simulate.md (Markdown) in this folder "
                  "(docs/configuration/)")
      ->check(CLI::ExistingDirectory);
  cmd->callback([a]() { run(*a); });
}

}  // namespace celc::app
