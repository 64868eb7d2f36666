#include "celc/pipeline/shipped_configs.hpp"

#include "celc/config/config.hpp"
#include "celc/core/yaml.hpp"
#include "celc/pipeline/run_config.hpp"

namespace celc {

std::vector<ShippedConfig> shippedConfigs() {
  const std::string generated =
      "Written by `celc config --write-defaults config/` from the schema; do not edit.\n";
  RunConfig run;
  SimulateConfig simulate;
  ClusterOptions cluster;
  LineFitOptions lines;
  return {
      {"run.yaml",
       writeYaml([&](FieldVisitor& v) { describe(v, run); },
                 {true, "celc run / celc batch: every key with its unit, meaning and default.\n" + generated +
                            "Use: celc run INPUT -c my.yaml (a file may hold any subset of the keys),\n"
                            "or --set section.key=value on the command line."}),
      },
      {"simulate.yaml",
       writeYaml([&](FieldVisitor& v) { describe(v, simulate); },
                 {true, "celc simulate: the paper's simulation study (Sec. 5.1), every key with its\n"
                        "unit, meaning and default.\n" + generated +
                            "Use: celc simulate -c my.yaml, or --set section.key=value."}),
      },
      {"cluster.yaml",
       writeYaml([&](FieldVisitor& v) { describeClustering(v, cluster, lines); },
                 {true, "The clustering and line-fitting keys alone (docs/clustering.md), with the\n"
                        "defaults of celc run and celc cluster.\n" + generated +
                            "Use: celc cluster EVENTS -c my.yaml, or as part of a run configuration."}),
      },
  };
}

}  // namespace celc
