#include "celc/eval/statistics.hpp"

#include <algorithm>
#include <cmath>

namespace celc {

double median(std::vector<double> x) {
  if (x.empty()) return NAN;
  const size_t n = x.size() / 2;
  std::nth_element(x.begin(), x.begin() + static_cast<long>(n), x.end());
  if (x.size() % 2) return x[n];
  return 0.5 * (x[n] + *std::max_element(x.begin(), x.begin() + static_cast<long>(n)));
}

double mean(const std::vector<double>& x) {
  if (x.empty()) return NAN;
  double s = 0.0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

double sampleStd(const std::vector<double>& x) {
  if (x.empty()) return NAN;
  if (x.size() == 1) return 0.0;
  const double m = mean(x);
  double ss = 0.0;
  for (double v : x) ss += (v - m) * (v - m);
  return std::sqrt(ss / static_cast<double>(x.size() - 1));
}

}  // namespace celc
