#include "celc/pipeline/batch.hpp"

#include <filesystem>

#include "celc/core/yaml.hpp"

namespace fs = std::filesystem;

namespace celc {

BatchSpec readBatch(const std::string& path,
                    const std::function<RunConfig(const std::string& base_config)>& make_base) {
  const fs::path dir = fs::path(path).parent_path();
  auto resolve = [&](std::string& p) {
    if (!p.empty() && !fs::path(p).is_absolute()) p = (dir / p).string();
  };
  BatchSpec spec;
  readYamlFile(path, [&](FieldVisitor& v) {
    v.field({"config", "", "base configuration file for every sequence (relative to this file)"},
            spec.base_config);
    resolve(spec.base_config);
    const RunConfig base = make_base(spec.base_config);
    v.require("sequences");
    std::size_t n = spec.entries.size();
    v.sequence({"sequences", "", "the sequences, each into OUTDIR/<label>/"}, n, [&](std::size_t i, FieldVisitor& s) {
      if (i == 0) spec.entries.assign(n, BatchEntry{});
      BatchEntry& e = spec.entries[i];
      e.config = base;
      s.require("path");
      s.field({"label", "", "output folder name (default: the input's file name)"}, e.label);
      s.field({"path", "", "recording: sequence folder or event file"}, e.inputs.events);
      s.field({"calib", "", "calibration YAML or calib.txt"}, e.inputs.calib);
      s.field({"groundtruth", "", "pose file"}, e.inputs.groundtruth);
      s.field({"imu", "", "IMU text file"}, e.inputs.imu);
      s.field({"t_start", "s", "first time used"}, e.t_start);
      s.field({"t_end", "s", "end of the time used"}, e.t_end);
      s.section({"config", "", "overrides of the base configuration (run.yaml keys)"},
                [&](FieldVisitor& c) { describe(c, e.config); });
      for (std::string* p : {&e.inputs.events, &e.inputs.calib, &e.inputs.groundtruth, &e.inputs.imu}) resolve(*p);
      if (e.label.empty()) e.label = fs::path(e.inputs.events).filename().string();
      for (std::size_t k = 0; k < i; ++k)
        if (spec.entries[k].label == e.label) s.fail("label", "duplicate label '" + e.label + "'");
      if (const std::string err = e.config.validate(); !err.empty()) s.fail("config", err);
    });
    if (n == 0) v.fail("sequences", "expected a non-empty list");
  });
  return spec;
}

}  // namespace celc
