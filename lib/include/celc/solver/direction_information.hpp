#pragma once
/// \file direction_information.hpp
/// Fisher information of the event-line likelihood about the velocity
/// direction, with every cluster's lines l1, l3 as nuisance parameters; used
/// for the Cramér-Rao bound (eval/crlb.hpp, at the true parameters) and for
/// the uncertainty of an estimate (at the estimate and the fitted lines, with
/// the robust scale of the residuals).
///
/// Model (the maximum-likelihood problem of method celc_ml): per cluster the
/// reference-frame plane normals m1 = R(t_s) l1, m3 = R(t_e) l3 (unit, 2 DoF
/// each) and the unit direction v (2 DoF) predict the line at any time; event
/// k's residual is its point-to-line distance d_k(v, m1, m3) [px]
/// (solver/celc_residual.hpp), d_k ~ N(0, sigma^2). With J the Jacobian of
/// all d_k with respect to the 2 tangent coordinates of v and the 4 of each
/// line, the unit-noise information is J^T J; its direction block after
/// eliminating the lines is the Schur complement
///   S = sum_c ( I_vv,c - I_vl,c I_ll,c^+ I_lv,c )   [1/rad^2 at sigma = 1 px]
/// (pseudo-inverse for a line's gauge freedoms). The covariance of the
/// direction at noise sigma is C = sigma^2 S^-1 (rad^2, tangent basis of v),
/// and its RMS angle sqrt(trace C) [rad].
#include <string>
#include <vector>

#include "celc/core/observations.hpp"
#include "celc/geometry/motion_model.hpp"
#include "celc/solver/celc_residual.hpp"

namespace celc {

struct DirectionInformation {
  bool ok = false;             ///< at least one event contributed
  std::string message;         ///< why not ok
  Eigen::Matrix2d schur = Eigen::Matrix2d::Zero();  ///< S at sigma = 1 px [1/rad^2]
  int events = 0;              ///< events used
  int lines = 0;               ///< clusters used
  /// The residuals d_k [px] of the events used (filled when asked for).
  std::vector<double> residuals_px;
};

/// S for `direction` (any non-zero length) and the clusters' l1, l3 as given
/// (with their times, l3.t > l1.t). `max_events`: at most about this many
/// events in all, a regular stride per cluster (0 = every event).
/// `keep_residuals` fills residuals_px.
DirectionInformation directionInformation(const WindowObservations& obs, const MotionModel& motion,
                                          const Vec3& direction, int max_events = 0,
                                          bool keep_residuals = false);

/// What directionInformation needs of a window that does not depend on the
/// direction: each usable cluster's frame and its events' terms (one pose of
/// the motion model per event), built once for the several directions a
/// window's estimates ask about.
/// A change of every bearing (x, y, 1) to (scale x + offset_x, scale y + offset_y, 1):
/// a calibration error (principal point offset / focal, focal share).
struct BearingChange {
  double scale = 1.0;
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
};

class DirectionTerms {
 public:
  /// `max_events` as for directionInformation; `bearing_change` applied to
  /// every event's bearing (null: none).
  DirectionTerms(const WindowObservations& obs, const MotionModel& motion, int max_events = 0,
                 const BearingChange* bearing_change = nullptr);
  ~DirectionTerms();
  DirectionTerms(const DirectionTerms&) = delete;
  DirectionTerms& operator=(const DirectionTerms&) = delete;
  /// directionInformation(obs, motion, direction, max_events, keep_residuals),
  /// the same numbers.
  DirectionInformation information(const Vec3& direction, bool keep_residuals = false) const;
  /// directionSigmaDeg(obs, motion, direction, scale, max_events).
  double sigmaDeg(const Vec3& direction, double scale) const;
  /// The first-order shift of the maximum-likelihood direction [rad, tangent
  /// basis of `direction`] when the measurements change from these terms to
  /// `changed`'s (the same window and max_events, another motion model or
  /// bearing change), the lines re-estimated: with g_k the change of event
  /// k's residual at the fixed estimate, shift = -S^-1 sum_c (J_v,c^T g_c -
  /// I_vl,c I_ll,c^+ J_l,c^T g_c), over the events within 3 robust scales
  /// (1.4826 median |d|) of their line at the estimate. NaN when S is
  /// singular or the events differ.
  Eigen::Vector2d shift(const Vec3& direction, const DirectionTerms& changed) const;
  /// shift() for each of `changed`, the same numbers; the unchanged terms'
  /// residuals, Jacobians and Schur blocks are computed once for all of them.
  std::vector<Eigen::Vector2d> shifts(const Vec3& direction,
                                      const std::vector<const DirectionTerms*>& changed) const;

 private:
  /// Cluster c's events: terms_[begin_[c], begin_[c + 1]); its plane
  /// normals m1_[c], m3_[c] (unit). The terms' memory is kept per thread
  /// across windows (as JointProblem's: a fresh block per window made the
  /// kernel map its pages every time).
  std::vector<EventTerm> terms_;
  std::vector<size_t> begin_{0};
  std::vector<Vec3> m1_, m3_;
  double focal_px_ = 0.0;
};

/// The covariance C = sigma_px^2 S^-1 [rad^2] and the RMS angle
/// sqrt(trace C) [rad]; +inf (and C infinite) when S is singular (the
/// direction unobservable: eigenvalue ratio below 1e-12).
struct DirectionCovariance {
  bool observable = false;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  double rms_rad = 0.0;
};
DirectionCovariance directionCovariance(const Eigen::Matrix2d& schur, double sigma_px);

/// The uncertainty of an estimate: S at the estimate `direction` and the
/// fitted lines of `obs`, sigma the robust scale of the residuals there
/// (1.4826 median |d_k| [px]), times `scale` (a per-method calibration, >= 0).
/// Returns the standard deviation of the direction sqrt(trace C) in degrees;
/// +inf when the direction is unobservable, NaN when no event is usable.
double directionSigmaDeg(const WindowObservations& obs, const MotionModel& motion,
                         const Vec3& direction, double scale, int max_events);

}  // namespace celc
