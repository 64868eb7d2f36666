#pragma once
// Internal: the one robust loss of the solvers, {type, scale}: the IRLS of
// the linear stage (irls_kernel), celc_opt's Ceres costs (refine_costs.hpp)
// and celc_ml's Levenberg-Marquardt (joint_refine, joint_kernel). On a
// residual d (pixels, or robust scales in the IRLS) with scale c:
//   Huber   rho = d^2 within c, 2 c |d| - c^2 beyond (the pull stays c);
//   Cauchy  rho = c^2 log(1 + d^2 / c^2) (the pull falls as c^2 / d);
//   Tukey   rho = c^2 / 3 (1 - (1 - d^2 / c^2)^3) within c, c^2 / 3 beyond
//           (no pull beyond c);
//   None    rho = d^2.
// Each loss is minimised in one of two forms: the square root of rho as
// the residual (sqrtResidual, for Ceres), or reweighted steps with the
// weights frozen at the point of linearisation (reweighted, for the own
// Levenberg-Marquardt). The functions are inline so that every pass keeps
// its own arithmetic where it is compiled (isa_clones.hpp).
#include <algorithm>
#include <cmath>

#include "isa_clones.hpp"

namespace celc::detail {

struct RobustLoss {
  enum class Type { None, Huber, Cauchy, Tukey };
  Type type = Type::None;
  double scale = 0.0;  ///< Huber's threshold, Cauchy's or Tukey's scale c [units of the residual]

  static RobustLoss huber(double c) { return {Type::Huber, c}; }
  static RobustLoss cauchy(double c) { return {Type::Cauchy, c}; }
  static RobustLoss tukey(double c) { return {Type::Tukey, c}; }

  /// rho(d), the event's cost.
  double rho(double d) const;
  /// The square-root form: r = sign(d) sqrt(rho(d)), so that sum r^2 = sum
  /// rho; returns r and dr/dd in *slope.
  double sqrtResidual(double d, double* slope) const;
};

/// The last refinement of celc_opt and celc_ml from its keys: none where
/// cauchy_scale is 0 or the residuals show no tail (scale_px(k) is 0 for
/// every k: ResidualSpread::cauchyScale); else Tukey's biweight at
/// scale_px(tukey_scale) when tukey_scale > 0, Cauchy's at
/// scale_px(cauchy_scale) otherwise.
template <class ScalePx>
RobustLoss redescendingLoss(double cauchy_scale, double tukey_scale, const ScalePx& scale_px) {
  if (!(cauchy_scale > 0.0)) return {};
  const bool tukey = tukey_scale > 0.0;
  const double c = scale_px(tukey ? tukey_scale : cauchy_scale);
  if (!(c > 0.0)) return {};
  return tukey ? RobustLoss::tukey(c) : RobustLoss::cauchy(c);
}

/// Huber in square-root form: r = d within delta, sign(d) sqrt(2 delta |d| -
/// delta^2) beyond; returns r and dr/dd.
inline double sqrtHuber(double d, double delta, double* slope) {
  const double a = std::abs(d);
  if (a <= delta) {
    *slope = 1.0;
    return d;
  }
  const double rho = 2.0 * delta * a - delta * delta;
  const double r = std::sqrt(rho);
  *slope = delta / r;
  return d < 0 ? -r : r;
}

/// Cauchy in square-root form: r = sign(d) c sqrt(log(1 + d^2 / c^2)).
inline double sqrtCauchy(double d, double c, double* slope) {
  const double q2 = (d / c) * (d / c);
  if (q2 < 1e-12) {
    *slope = 1.0;
    return d;
  }
  const double r = c * std::sqrt(std::log1p(q2));
  *slope = std::abs(d) / (r * (1.0 + q2));
  return d < 0 ? -r : r;
}

/// Tukey's biweight in square-root form; beyond c the slope is 0.
inline double sqrtTukey(double d, double c, double* slope) {
  const double q2 = (d / c) * (d / c);
  if (q2 < 1e-12) {
    *slope = 1.0;
    return d;
  }
  if (q2 >= 1.0) {
    *slope = 0.0;
    return d < 0 ? -c / std::sqrt(3.0) : c / std::sqrt(3.0);
  }
  const double u = 1.0 - q2;
  const double r = c * std::sqrt((1.0 - u * u * u) / 3.0);
  *slope = std::abs(d) * u * u / r;
  return d < 0 ? -r : r;
}

inline double RobustLoss::sqrtResidual(double d, double* slope) const {
  switch (type) {
    case Type::Huber: return sqrtHuber(d, scale, slope);
    case Type::Cauchy: return sqrtCauchy(d, scale, slope);
    case Type::Tukey: return sqrtTukey(d, scale, slope);
    case Type::None: break;
  }
  *slope = 1.0;
  return d;
}

inline double RobustLoss::rho(double d) const {
  if (type == Type::Tukey) {
    const double q = d / scale, t = std::max(0.0, 1.0 - q * q);
    return scale * scale / 3.0 * (1.0 - t * t * t);
  }
  if (type == Type::Cauchy) {
    const double q = d / scale;
    return scale * scale * std::log1p(q * q);
  }
  if (type == Type::None) return d * d;
  double slope;
  const double r = sqrtHuber(d, scale, &slope);
  return r * r;
}

/// A residual in the reweighted form and its slope: r = slope d with the
/// slope the square root of the loss's IRLS weight at d (Huber: its
/// square-root form).
struct ReweightedRoot {
  double r, slope;
};
/// The reweighted form of loss T at scale c, branch-free so that a pass
/// forms several events at once: Huber's square-root form, Cauchy's
/// r = d / sqrt(1 + d^2 / c^2), Tukey's r = (1 - d^2 / c^2) d within c and
/// 0 beyond, None's r = d.
template <RobustLoss::Type T>
CELC_PASS_INLINE ReweightedRoot reweighted(double d, double scale) {
  ReweightedRoot out;
  if (T == RobustLoss::Type::Huber) {
    const double a = std::abs(d);
    const bool inside = a <= scale;
    const double root = std::sqrt(inside ? 1.0 : 2.0 * scale * a - scale * scale);
    out.slope = inside ? 1.0 : scale / root;
    out.r = inside ? d : (d < 0.0 ? -root : root);
  } else if (T == RobustLoss::Type::Cauchy) {
    const double q = d / scale;
    out.slope = 1.0 / std::sqrt(1.0 + q * q);
    out.r = out.slope * d;
  } else if (T == RobustLoss::Type::Tukey) {
    const double q = d / scale;
    const double t = 1.0 - q * q;
    out.slope = t > 0.0 ? t : 0.0;
    out.r = out.slope * d;
  } else {
    out.slope = 1.0;
    out.r = d;
  }
  return out;
}

}  // namespace celc::detail
