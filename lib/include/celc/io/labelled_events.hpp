#pragma once
/// \file labelled_events.hpp
/// Events already labelled by cluster, for `celc solve`: CSV with the header
/// `t,x,y,cluster` (seconds; pixels, or normalised coordinates; integer
/// cluster id, -1 = unassigned). Errors name the file and the line.
#include <string>
#include <vector>

namespace celc {

struct LabelledEvent {
  double t = 0.0;
  double x = 0.0, y = 0.0;
  int cluster = -1;
};

/// Reads the whole file; throws std::runtime_error("FILE:LINE: ...") on a
/// missing or wrong header, a wrong column count, a non-numeric or non-finite field.
std::vector<LabelledEvent> readLabelledEvents(const std::string& path);

/// Writes `content` to `path` through a temporary file in the same folder and
/// a rename, so that a reader never sees a half-written file. Throws on error.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace celc
