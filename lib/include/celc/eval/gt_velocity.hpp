#pragma once
/// \file gt_velocity.hpp
/// Ground-truth camera-frame linear velocity from a pose file.
/// Poses are T_world_body(t); the camera is T_world_cam = T_world_body * T_body_cam,
/// so p_wc(t) = p_wb(t) + R_wb(t) t_bc and R_wc(t) = R_wb(t) R_bc.
/// The velocity at time t is v_cam(t) = R_wc(t)^T dp_wc/dt, where dp_wc/dt is the
/// linear coefficient of a least-squares polynomial (degree `degree`) fitted to
/// the camera positions within +-half_width of t (tau = t_i - t), and R_wc(t) is
/// interpolated by slerp. The window value is the mean of v_cam over
/// `samples` equally spaced times in [t0, t1).
#include <string>
#include <vector>

#include "celc/core/fields.hpp"
#include "celc/core/types.hpp"

namespace celc {

struct GtVelocityOptions {
  double half_width = 0.05;  ///< [s] fit neighbourhood on each side
  int degree = 2;            ///< polynomial degree (1..4)
  int min_poses = 5;         ///< poses needed inside the neighbourhood
  int samples = 11;          ///< evaluation times per window
  std::string validate() const;
};
/// The schema of the `groundtruth:` section (core/fields.hpp).
void describe(FieldVisitor& v, GtVelocityOptions& options);


enum class GtStatus { Ok, NotCovered, TooFewPoses, InvalidWindow };
std::string toString(GtStatus s);  ///< "ok", "gt_not_covered", "gt_too_few_poses", "invalid_window"

struct GtVelocity {
  GtStatus status = GtStatus::NotCovered;
  Vec3 v_cam = Vec3::Zero();  ///< mean camera-frame velocity [m/s]
  bool ok() const { return status == GtStatus::Ok; }
};

class GtVelocityEstimator {
 public:
  /// poses: strictly increasing times (readPosesText guarantees it).
  GtVelocityEstimator(std::vector<PoseSample> poses, const Eigen::Matrix4d& T_body_cam = Eigen::Matrix4d::Identity(),
                      const GtVelocityOptions& options = {});
  /// Camera-frame velocity at t.
  GtVelocity at(double t) const;
  /// Mean over [t0, t1).
  GtVelocity window(double t0, double t1) const;

 private:
  std::vector<PoseSample> poses_;
  std::vector<Vec3> p_cam_;  ///< camera positions in the world
  Mat3 R_bc_;
  GtVelocityOptions o_;
};

}  // namespace celc
