#pragma once
/// \file motion_model.hpp
/// Camera motion over one window, relative to the camera at a reference time
/// t_ref. For any time t the model gives
///   R(t) = R_ref_t   (rotation of the camera at t, expressed in the reference camera frame)
///   p(t) = P(t) v    (position of the camera at t in the reference frame; linear in v)
/// so that a point X_t in the camera frame at t is R(t) X_t + p(t) in the reference frame.
///
/// Two models:
///  - ConstantTwist (the paper's): constant body twist (v, w);
///      R(t) = exp(w^ tau),  P(t) = J_l(w tau) tau,  tau = t - t_ref.
///    v is the body-frame velocity, the same at every time of the window.
///  - GyroIntegrated: R(t) integrated from a sampled angular-velocity signal
///    (linear interpolation between samples), with the velocity constant
///      - in the body frame (VelocityFrame::Body, the pipeline's): P(t) =
///        integral of R(s) ds over [t_ref, t]; v is the body-frame velocity, and
///        with a constant rate this is the constant twist;
///      - or in the reference frame (VelocityFrame::Reference, the newer
///        papers' protocol, docs/accuracy.md): P(t) = tau I; v is the velocity in
///        the reference camera frame.
/// Both keep every CELC constraint linear in v.
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

enum class MotionModelKind { ConstantTwist, GyroIntegrated };
/// GyroIntegrated: the frame in which the linear velocity is constant.
enum class VelocityFrame { Body, Reference };

/// Parses "constant_twist" / "gyro_integrated"; throws std::invalid_argument otherwise.
MotionModelKind parseMotionModelKind(const std::string& name);
std::string toString(MotionModelKind kind);

class MotionModel {
 public:
  /// Constant angular velocity w [rad/s, camera frame] about t_ref [s].
  static MotionModel constantTwist(const Vec3& omega, double t_ref);
  /// Angular-velocity samples (times [s], increasing; rates [rad/s] in the camera
  /// frame), integrated with the trapezoidal rule. Needs at least one sample;
  /// outside the sampled range the nearest end rate is held.
  static MotionModel gyroIntegrated(const std::vector<double>& times,
                                    const std::vector<Vec3>& rates, double t_ref,
                                    VelocityFrame frame = VelocityFrame::Body);

  MotionModelKind kind() const { return kind_; }
  /// Body for ConstantTwist; GyroIntegrated: as built.
  VelocityFrame velocityFrame() const { return frame_; }
  double referenceTime() const { return t_ref_; }
  /// Mean angular velocity over [t0, t1] [rad/s]: the constant rate, or log(R(t0)^T R(t1)) / (t1 - t0).
  Vec3 meanOmega(double t0, double t1) const;

  /// R_ref_t.
  Mat3 rotation(double t) const;
  /// P(t) with p_ref_t = P(t) v.
  Mat3 positionMatrix(double t) const;
  /// R(t) and P(t) together (one sin/cos for the constant twist).
  void pose(double t, Mat3& R, Mat3& P) const;

  /// R(t) x (x in the camera at t, the result in the reference frame), as
  /// rotation(t) * x up to rounding, without forming R(t).
  Vec3 rotate(double t, const Vec3& x) const;

  /// R(t)^T x and P(t)^T x for two reference-frame vectors x = a, b.
  struct TransposedActions {
    Vec3 Rt_a, Rt_b, Pt_a, Pt_b;
  };
  /// The same numbers as pose() then R^T x, P^T x (up to rounding), without
  /// forming R and P: with the step exp(phi) that pose() composes (phi = w tau
  /// for the constant twist; R_i exp(phi) from the sample i before t for the
  /// gyro), exp(phi)^T y = y - A phi x y + B phi x (phi x y) and
  /// J_l(phi)^T y = y - B phi x y + C phi x (phi x y) (so3::coefficients).
  TransposedActions transposedActions(double t, const Vec3& a, const Vec3& b) const;

  /// GyroIntegrated: the rotation over one piece of the samples, for kernels
  /// that evaluate many times at once. For t in the piece, dt = t - t0:
  ///   R(t) = R0 exp(phi),  phi = (w0 + h dt) dt  (the step turns at the mean
  ///   of the rates at t0 and t),
  ///   P(t) = P0 + R0 J_l(phi) dt (Body) or (t - t_ref) I (Reference).
  /// Piece 0 lies before the first sample and piece n (n samples) after the
  /// last (the end rate held, h = 0); piece i in 1..n-1 between samples i-1
  /// and i.
  struct RotationPiece {
    double t0 = 0.0;
    Vec3 w0 = Vec3::Zero(), h = Vec3::Zero();
    Mat3 R0 = Mat3::Identity(), P0 = Mat3::Zero();
  };
  /// GyroIntegrated: the piece that holds t (0 for ConstantTwist).
  size_t pieceIndex(double t) const;
  /// GyroIntegrated: piece `index` (<= the sample count).
  RotationPiece piece(size_t index) const;

  /// The same model with a different constant rate (ConstantTwist) or with all
  /// rate samples shifted by delta (GyroIntegrated): used to perturb the gyroscope.
  MotionModel withOmegaOffset(const Vec3& delta) const;
  /// The same model with every rate w replaced by A w + delta (a gyroscope's
  /// scale, misalignment and bias errors; solver/error_budget.hpp).
  MotionModel withRateTransform(const Mat3& A, const Vec3& delta) const;

 private:
  MotionModelKind kind_ = MotionModelKind::ConstantTwist;
  VelocityFrame frame_ = VelocityFrame::Body;
  double t_ref_ = 0.0;
  Vec3 omega_ = Vec3::Zero();
  // GyroIntegrated: samples and R_ref_ti at each sample time.
  std::vector<double> times_;
  std::vector<Vec3> rates_;
  std::vector<Mat3> rotations_;
  std::vector<Mat3> positions_;  ///< P at each sample time
  /// (samples - 1) / (last time - first time) [1/s]: pieceIndex's first guess.
  double samples_per_s_ = 0.0;
  /// GyroIntegrated: R(t) and P(t) from the samples (rotations_ / positions_
  /// anchored at t_ref, or from the first sample while they are being built);
  /// P is skipped when null.
  void samplePose(double t, Mat3& R, Mat3* P) const;
  /// GyroIntegrated: the sample i whose step holds t, and that step's
  /// rotation vector phi (R(t) = rotations_[i] exp(phi)) and length dt [s].
  void sampleStep(double t, size_t& i, Vec3& phi, double& dt) const;
  /// GyroIntegrated: h of the piece between samples i and i + 1 (half the
  /// rate's slope: the mean of the rates at t_i and t_i + dt is w_i + h dt).
  Vec3 rateSlope(size_t i) const;
};

}  // namespace celc
