#pragma once
/// \file batch.hpp
/// BATCH.yaml of `celc batch`: a base configuration and a list of sequences,
/// each with its inputs, time range and configuration overrides
/// (config/batch_example.yaml). One schema (core/fields.hpp); errors are
/// ConfigError naming the file, the line and the key.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/sequence_runner.hpp"

namespace celc {

struct BatchEntry {
  std::string label;  ///< output folder name; default: the input's file name
  RunInputs inputs;   ///< paths resolved against the batch file's folder
  double t_start = -std::numeric_limits<double>::infinity();  ///< [s]
  double t_end = std::numeric_limits<double>::infinity();     ///< [s]
  RunConfig config;   ///< the base configuration with this entry's overrides
};

struct BatchSpec {
  std::string base_config;  ///< `config:` path, resolved (empty: none)
  std::vector<BatchEntry> entries;
};

/// Reads BATCH.yaml. `make_base(base_config)` builds the configuration that
/// every entry's `config:` overrides apply onto (the caller adds its
/// command-line options there); labels must be unique.
BatchSpec readBatch(const std::string& path,
                    const std::function<RunConfig(const std::string& base_config)>& make_base);

}  // namespace celc
