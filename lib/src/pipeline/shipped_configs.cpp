#include "celc/pipeline/shipped_configs.hpp"

#include "celc/config/config.hpp"
#include "celc/core/yaml.hpp"
#include "celc/pipeline/run_config.hpp"

namespace celc {
namespace {

/// A table cell: pipes escaped, so that a doc or a value never splits a row.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += "\\|";
    else if (c == '\n') out += ' ';
    else out += c;
  }
  return out;
}

/// One Markdown table per top-level section of `describe`'s keys.
std::string markdownReference(const Describe& describe, const std::string& title, const std::string& intro) {
  std::string out = "# " + title + "\n\n" + intro +
                    "\n\nWritten by `celc config --write-reference docs/configuration/` from the schema; do not "
                    "edit.\n";
  std::string section;
  for (const FieldEntry& f : listFields(describe)) {
    const std::string head = f.key.substr(0, f.key.find_first_of(".["));
    if (head != section) {
      section = head;
      out += "\n## " + section + "\n\n| key | default | unit | valid | meaning |\n|---|---|---|---|---|\n";
    }
    std::string valid = f.range;
    for (std::size_t k = 0; k < f.choices.size(); ++k) valid += (k == 0 ? "" : ", ") + ("`" + f.choices[k] + "`");
    out += "| `" + cell(f.key) + "` | `" + cell(f.value) + "` | " + cell(f.unit) + " | " + cell(valid) + " | " +
           cell(f.doc) + " |\n";
  }
  return out;
}

}  // namespace

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

std::vector<ShippedConfig> shippedReferences() {
  RunConfig run;
  SimulateConfig simulate;
  return {
      {"run.md", markdownReference([&](FieldVisitor& v) { describe(v, run); }, "celc run and celc batch: keys",
                                   "Every key of a run configuration (`-c FILE`, `--set key=value`) with its "
                                   "default and unit. `config/run.yaml` holds the same defaults as YAML.")},
      {"simulate.md",
       markdownReference([&](FieldVisitor& v) { describe(v, simulate); }, "celc simulate: keys",
                         "Every key of a simulation study's configuration (`celc simulate -c FILE`, `--set "
                         "key=value`) with its default and unit. `config/simulate.yaml` holds the same defaults "
                         "as YAML.")},
  };
}

}  // namespace celc
