#pragma once
/// \file shipped_configs.hpp
/// The configuration files shipped in config/ that list every key with its
/// unit, doc and default: written from the schema (core/fields.hpp), never by
/// hand. `celc config --write-defaults config/` regenerates them; a test fails
/// when a shipped file differs from what the schema writes.
#include <string>
#include <vector>

namespace celc {

struct ShippedConfig {
  std::string file;  ///< name inside config/, e.g. "run.yaml"
  std::string text;  ///< its full content
};

/// config/run.yaml (RunConfig defaults), config/simulate.yaml (SimulateConfig
/// defaults) and config/cluster.yaml (the clustering sections alone).
std::vector<ShippedConfig> shippedConfigs();

/// docs/configuration/run.md and simulate.md: the key reference as Markdown
/// tables (key, default, unit, meaning), one table per top-level section,
/// from the same schema. `celc config --write-reference docs/configuration/`
/// regenerates them; a test fails when the committed pages differ.
std::vector<ShippedConfig> shippedReferences();

}  // namespace celc
