#pragma once
// The run configuration of the Python calls (celc.solve, celc.run): what
// `celc run -c FILE --set ...` builds, from Python values.
#include "celc/pipeline/run_config.hpp"
#include "common.hpp"

namespace celc::py {

/// Defaults, then `config` (a YAML path, a dict over the run schema or None),
/// then `set` (a dict or "key=value" strings), then `methods` (a list of names
/// or "a,b"; None keeps the configuration's); validated. `origin` names the
/// call in errors (ConfigError -> ValueError).
RunConfig runConfig(const pyb::handle& config, const pyb::handle& set, const pyb::handle& methods,
                    const std::string& origin);

}  // namespace celc::py
