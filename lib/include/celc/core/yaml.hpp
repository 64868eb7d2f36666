#pragma once
/// \file yaml.hpp
/// The one YAML reader and writer of every configuration file (run, simulate,
/// batch, scene, calibration), as visitors over a describe() function
/// (core/fields.hpp). Errors are ConfigError "FILE:LINE: key 'a.b': what".
#include <string>
#include <vector>

#include "celc/core/fields.hpp"

namespace celc {

/// Applies a YAML document onto the fields that `describe` visits; keys it
/// does not hold keep their values. Rejected, with file, line and key: YAML
/// syntax errors, unknown keys (with the keys allowed there), a key given
/// twice in one map, values of the wrong type or out of the type's range,
/// NaN, lists of the wrong length, names outside a choice.
void readYaml(const std::string& text, const std::string& origin, const Describe& describe);
/// readYaml of a document the program generated (from `--set` assignments, a
/// Python dict): errors name the origin and the key, not the generated lines.
void readGeneratedYaml(const std::string& text, const std::string& origin, const Describe& describe);
/// The same from a file (ConfigError when it cannot be opened).
void readYamlFile(const std::string& path, const Describe& describe);

struct YamlWriteOptions {
  bool comments = true;  ///< `# [unit] doc` after each value, section docs above sections
  std::string header;    ///< comment lines written first (each prefixed with "# ")
};
/// Every field as YAML, in describe() order; values read back exactly
/// (numbers at round-trip precision).
std::string writeYaml(const Describe& describe, const YamlWriteOptions& options = {});

/// Applies one `key.path=value` assignment (a YAML value) onto `describe`'s
/// fields; errors name the assignment ("--set a.b=x: ...").
void applyAssignment(const std::string& assignment, const Describe& describe);

/// "doc [unit] (YAML key.path, default VALUE)" for one dotted key, from the
/// schema and the values `describe` currently holds; throws std::logic_error
/// when the key is not in the schema.
std::string fieldHelp(const Describe& describe, const std::string& dotted_key);

/// One field of a schema with the value it holds (as YAML text).
struct FieldEntry {
  std::string key;    ///< dotted, list items as "planes[0].texture"
  std::string unit;
  std::string doc;
  std::string value;  ///< YAML text, exactly as writeYaml writes it
  std::vector<std::string> choices;  ///< the allowed names of an enumeration (empty otherwise)
  std::string range;  ///< the valid numbers, Range::text() ("" when any)
};
/// Every field `describe` visits, in order, with its value: to compare two
/// configurations field by field or to list the schema.
std::vector<FieldEntry> listFields(const Describe& describe);

}  // namespace celc
