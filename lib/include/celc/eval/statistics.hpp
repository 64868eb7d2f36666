#pragma once
/// \file statistics.hpp
/// Sample statistics used by the studies and the tables (NaN for no data).
#include <vector>

namespace celc {

/// Median (mean of the two middle values for an even count).
double median(std::vector<double> x);
/// Arithmetic mean.
double mean(const std::vector<double>& x);
/// Sample standard deviation (n - 1), 0 for one value.
double sampleStd(const std::vector<double>& x);

}  // namespace celc
