#pragma once
/// \file error_budget.hpp
/// The part of an estimate's uncertainty that the Fisher information cannot
/// see: errors of the inputs the solvers take as exact. Each source k of
/// UncertaintyOptions' budget is a change of the measurements of its 1-sigma
/// size (a gyroscope bias, scale or IMU-camera rotation about one axis: the
/// rates w become A w + delta; a principal point offset along one image axis
/// or a focal length error: every bearing moves), and its first-order effect
/// on the maximum-likelihood direction, the lines re-estimated, is
/// DirectionTerms::shift. The sources are taken as independent:
///   sigma_B = sqrt(sum_k |shift_k|^2)   [rad]
/// A rate error moves the image by about focal |delta w| T px over a window
/// of T seconds, against the translation's D px, so sigma_B grows as 1/D
/// where the window shows little parallax.
#include <memory>
#include <vector>

#include "celc/solver/direction_information.hpp"
#include "celc/solver/options.hpp"

namespace celc {

class ErrorBudget {
 public:
  /// The changed terms of every source with a non-zero size in `options`
  /// (the events as in DirectionTerms(obs, motion, options.max_events)).
  ErrorBudget(const WindowObservations& obs, const MotionModel& motion, const UncertaintyOptions& options);
  ~ErrorBudget();
  ErrorBudget(const ErrorBudget&) = delete;
  ErrorBudget& operator=(const ErrorBudget&) = delete;
  /// sigma_B [deg] at `direction`, `base` the window's unchanged terms (the
  /// same obs, motion and max_events). 0 with no source; NaN where a shift is
  /// not defined (the direction unobservable).
  double sigmaDeg(const DirectionTerms& base, const Vec3& direction) const;
  /// The number of sources.
  size_t sources() const { return changed_.size(); }

 private:
  std::vector<std::unique_ptr<DirectionTerms>> changed_;
};

}  // namespace celc
