#pragma once
/// \file text.hpp
/// Small text helpers shared by the command line and the readers, so that a
/// list such as `celc,ce3lc` or `0,0,2` is split the same way everywhere.
#include <string>
#include <string_view>
#include <vector>

namespace celc {

/// The fields of `text` between separators, as written (not trimmed): n
/// separators give n + 1 fields, empty ones included (`a,,b,` gives a, "",
/// b, ""), so that a missing value is seen rather than skipped. Empty text
/// gives no field.
std::vector<std::string> splitList(std::string_view text, char separator = ',');

/// `text` without leading and trailing blanks (space, tab, carriage return).
std::string trimBlanks(std::string_view text);

}  // namespace celc
