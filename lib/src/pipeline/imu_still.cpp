// The first still second of an IMU stream (imu_still.hpp).
#include "celc/pipeline/imu_still.hpp"

#include <algorithm>
#include <cmath>

namespace celc {

StillSpan findFirstStill(const std::vector<ImuSample>& imu, const StillOptions& o) {
  StillSpan out;
  if (imu.empty()) return out;
  const double t_first = imu.front().t, t_last = imu.back().t;
  std::size_t begin = 0;
  for (double t0 = t_first; t0 + o.span_s <= t_last + 1e-9; t0 += o.step_s) {
    while (begin < imu.size() && imu[begin].t < t0) ++begin;
    const double t1 = t0 + o.span_s;
    Vec3 gs = Vec3::Zero(), gq = Vec3::Zero();
    double as = 0.0, aq = 0.0;
    int n = 0;
    for (std::size_t k = begin; k < imu.size() && imu[k].t < t1; ++k) {
      const Vec3& g = imu[k].gyro;
      if (!g.allFinite() || !imu[k].accel.allFinite()) continue;
      gs += g;
      gq += g.cwiseProduct(g);
      const double a = imu[k].accel.norm();
      as += a;
      aq += a * a;
      ++n;
    }
    if (n < o.min_samples) continue;
    const Vec3 gm = gs / n;
    const Vec3 gstd = (gq / n - gm.cwiseProduct(gm)).cwiseMax(0.0).cwiseSqrt();
    const double am = as / n, astd = std::sqrt(std::max(0.0, aq / n - am * am));
    if (gstd.maxCoeff() <= o.max_gyro_std && am > 0.0 && astd <= o.max_accel_rel_std * am) {
      out.found = true;
      out.t0 = t0;
      out.t1 = t1;
      out.samples = n;
      out.gyro_mean = gm;
      out.gyro_std = gstd;
      return out;
    }
  }
  return out;
}

}  // namespace celc
