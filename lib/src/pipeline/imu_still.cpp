// The first still second of an IMU stream (imu_still.hpp).
#include "celc/pipeline/imu_still.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace celc {

namespace {

std::string format(const char* f, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

}  // namespace

void describe(FieldVisitor& v, StillOptions& o) {
  v.field({"span_s", "s", "length of the span", above(0)}, o.span_s);
  v.field({"step_s", "s", "between candidate starts", above(0)}, o.step_s);
  v.field({"max_gyro_std", "rad/s", "largest gyro std per axis", atLeast(0)}, o.max_gyro_std);
  v.field({"max_accel_turn", "rad", "largest turn of the accelerometer direction over the span", atLeast(0)},
          o.max_accel_turn);
  v.field({"max_accel_rel_std", "-", "largest std / mean of |accel|", atLeast(0)}, o.max_accel_rel_std);
  v.field({"max_mean_rate", "rad/s", "largest norm of the mean gyro rate", atLeast(0)}, o.max_mean_rate);
  v.field({"min_samples", "samples", "a span needs this many", atLeast(10)}, o.min_samples);
}

std::string StillOptions::validate() const { return rangeProblemsOf(*this); }

bool StillSpan::significant(double z, double min_rate) const {
  if (!found || samples <= 0 || gyro_mean.norm() < min_rate) return false;
  const double root_n = std::sqrt(static_cast<double>(samples));
  for (int i = 0; i < 3; ++i)
    if (std::abs(gyro_mean[i]) >= z * gyro_std[i] / root_n && gyro_mean[i] != 0.0) return true;
  return false;
}

StillSpan findFirstStill(const std::vector<ImuSample>& imu, const StillOptions& o) {
  StillSpan out;
  if (imu.empty()) {
    out.refused = "no IMU samples";
    return out;
  }
  // An IMU without accelerometer writes zeros there.
  out.has_accel = std::any_of(imu.begin(), imu.end(), [](const ImuSample& s) {
    return s.accel.allFinite() && !s.accel.isZero(0.0);
  });
  if (!out.has_accel)
    out.warning = "the IMU has no accelerometer (every sample 0): rest judged from the gyro alone, so a "
                  "steady rotation below " + format("%.2f", o.max_mean_rate) + " rad/s reads as a bias";
  const double t_first = imu.front().t, t_last = imu.back().t;
  if (t_first + o.span_s > t_last + 1e-9) {
    out.refused = format("the IMU covers %.3f s, less than a span of %g s", t_last - t_first, o.span_s);
    return out;
  }
  std::size_t begin = 0;
  std::vector<std::size_t> in_span;
  bool first = true;
  for (double t0 = t_first; t0 + o.span_s <= t_last + 1e-9; t0 += o.step_s, first = false) {
    while (begin < imu.size() && imu[begin].t < t0) ++begin;
    const double t1 = t0 + o.span_s;
    in_span.clear();
    Vec3 gs = Vec3::Zero(), gq = Vec3::Zero(), avs = Vec3::Zero(), avq = Vec3::Zero();
    double as = 0.0, aq = 0.0;
    for (std::size_t k = begin; k < imu.size() && imu[k].t < t1; ++k) {
      const Vec3& g = imu[k].gyro;
      if (!g.allFinite() || !imu[k].accel.allFinite()) continue;
      in_span.push_back(k);
      gs += g;
      gq += g.cwiseProduct(g);
      avs += imu[k].accel;
      avq += imu[k].accel.cwiseProduct(imu[k].accel);
      const double a = imu[k].accel.norm();
      as += a;
      aq += a * a;
    }
    const int n = static_cast<int>(in_span.size());
    const std::string where = format("[%.3f, %.3f] s", t0, t1);
    if (n < o.min_samples) {
      if (first) out.refused = "the first span " + where + format(": only %.0f IMU samples", n);
      continue;
    }
    const Vec3 gm = gs / n;
    const Vec3 gstd = (gq / n - gm.cwiseProduct(gm)).cwiseMax(0.0).cwiseSqrt();
    std::string why;
    const auto refuse = [&](const std::string& r) { why += (why.empty() ? "" : "; ") + r; };
    // (a) the gyro shows noise only.
    if (gstd.maxCoeff() > o.max_gyro_std)
      refuse(format("the gyro varies (std up to %.3f rad/s, more than %g)", gstd.maxCoeff(), o.max_gyro_std));
    // (b) the accelerometer: its norm steady and its direction still.
    double turn = 0.0;
    if (out.has_accel) {
      const double am = as / n, astd = std::sqrt(std::max(0.0, aq / n - am * am));
      if (!(am > 0.0) || astd > o.max_accel_rel_std * am)
        refuse(format("the accelerometer norm varies by %.1f%% (more than %g%%)", am > 0.0 ? 100.0 * astd / am : 100.0,
                      100.0 * o.max_accel_rel_std));
      const int fifth = std::max(1, n / 5);
      Vec3 a_head = Vec3::Zero(), a_tail = Vec3::Zero();
      double t_head = 0.0, t_tail = 0.0;
      for (int k = 0; k < fifth; ++k) {
        a_head += imu[in_span[static_cast<std::size_t>(k)]].accel;
        t_head += imu[in_span[static_cast<std::size_t>(k)]].t;
        a_tail += imu[in_span[static_cast<std::size_t>(n - 1 - k)]].accel;
        t_tail += imu[in_span[static_cast<std::size_t>(n - 1 - k)]].t;
      }
      const double dt = (t_tail - t_head) / fifth;
      if (a_head.norm() > 0.0 && a_tail.norm() > 0.0 && dt > 0.0) {
        const double angle = std::atan2(a_head.cross(a_tail).norm(), a_head.dot(a_tail));
        turn = angle * o.span_s / dt;
      }
      if (turn > o.max_accel_turn)
        refuse(format("the accelerometer direction turns %.3f rad in %g s (more than %g rad): the camera turns", turn,
                      o.span_s, o.max_accel_turn));
    }
    // (c) the mean rate is one a bias may have.
    if (gm.norm() > o.max_mean_rate)
      refuse(format("the gyro reads a steady %.3f rad/s, more than a bias (%g rad/s): a camera turning, not one "
                    "at rest",
                    gm.norm(), o.max_mean_rate));
    if (!why.empty()) {
      if (first) out.refused = "the first span " + where + ": " + why;
      continue;
    }
    out.found = true;
    out.t0 = t0;
    out.t1 = t1;
    out.samples = n;
    out.gyro_mean = gm;
    out.gyro_std = gstd;
    out.accel_turn = turn;
    out.accel_mean = avs / n;
    out.accel_std = (avq / n - out.accel_mean.cwiseProduct(out.accel_mean)).cwiseMax(0.0).cwiseSqrt();
    out.refused.clear();
    return out;
  }
  return out;
}

}  // namespace celc
