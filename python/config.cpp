#include "config.hpp"

#include "celc/core/text.hpp"

namespace celc::py {

RunConfig runConfig(const pyb::handle& config, const pyb::handle& set, const pyb::handle& methods,
                    const std::string& origin) {
  RunConfig c;
  const Describe schema = [&](FieldVisitor& v) { describe(v, c); };
  if (pyb::isinstance<pyb::dict>(config)) applyDict(config, origin + "(config)", schema);
  else if (!config.is_none()) c = loadRunConfig(existingPath(config));
  applyDict(set, origin + "(set)", schema);
  if (!methods.is_none()) {
    std::string list;
    if (pyb::isinstance<pyb::str>(methods)) list = methods.cast<std::string>();
    else
      for (auto m : methods) list += (list.empty() ? "" : ",") + pyb::str(m).cast<std::string>();
    try {
      c.methods = parseMethodList(list);
    } catch (const std::exception& e) {
      throw ConfigError(origin + "(methods): " + e.what());
    }
  }
  if (const std::string err = c.validate(); !err.empty()) throw ConfigError(origin + ": configuration: " + err);
  return c;
}

}  // namespace celc::py
