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

/// A byte count computed in floating point (a product of sizes read from a
/// file, possibly beyond 2^64, or NaN) as decimal text for an error message:
/// the integer below 2^64, else "more than 2^64" (positive) or "an invalid
/// number of" (negative, NaN); never a float-to-integer overflow.
std::string byteCountText(double bytes);

/// A finite double as the shortest of "%.15g" and "%.17g" that reads back to
/// the same value ("0.5", "1e-10", "2"); callers spell NaN and infinities.
std::string roundTripText(double x);

}  // namespace celc
