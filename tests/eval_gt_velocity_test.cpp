// Ground-truth camera-frame velocity from poses: analytic trajectories.
#include <gtest/gtest.h>

#include <cmath>

#include "celc/eval/gt_velocity.hpp"
#include "celc/geometry/so3.hpp"

using namespace celc;
using namespace celc;

namespace {
Eigen::Matrix4d someTBodyCam() {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = so3::exp(Vec3(0.2, -0.4, 0.1));
  T.topRightCorner<3, 1>() = Vec3(0.05, -0.02, 0.1);
  return T;
}
}  // namespace

/// Constant body twist (v_b, w_b) of the camera: p_wc(t) = J_l(w t) v t,
/// R_wc(t) = exp(w t); the camera-frame velocity is v_b at every time.
TEST(EvalGtVelocity, ConstantTwistThroughTBodyCam) {
  const Vec3 v(0.8, -0.3, 0.5), w(0.3, 0.5, -0.4);
  const Eigen::Matrix4d T_bc = someTBodyCam();
  const Mat3 R_bc = T_bc.topLeftCorner<3, 3>();
  const Vec3 t_bc = T_bc.topRightCorner<3, 1>();
  std::vector<PoseSample> poses;
  for (int i = 0; i <= 2000; ++i) {  // 200 Hz over 10 s
    const double t = 0.005 * i;
    const Mat3 R_wc = so3::exp(w * t);
    const Vec3 p_wc = so3::leftJacobian(w * t) * v * t;
    // body pose from camera pose: T_wb = T_wc T_bc^-1
    const Mat3 R_wb = R_wc * R_bc.transpose();
    const Vec3 p_wb = p_wc - R_wb * t_bc;
    PoseSample p;
    p.t = t;
    p.position = p_wb;
    p.orientation = Eigen::Quaterniond(R_wb);
    poses.push_back(p);
  }
  GtVelocityEstimator est(poses, T_bc);
  for (double t0 : {1.0, 4.321, 8.5}) {
    const GtVelocity g = est.window(t0, t0 + 0.2);
    ASSERT_TRUE(g.ok());
    EXPECT_LT((g.v_cam - v).norm() / v.norm(), 1e-3) << g.v_cam.transpose();
  }
}

/// A circle of radius r at angular rate W, camera looking at the centre:
/// in the camera frame the velocity is constant, r W along the tangent axis.
TEST(EvalGtVelocity, CircleLookingInward) {
  const double r = 2.0, W = 0.7;
  std::vector<PoseSample> poses;
  for (int i = 0; i <= 3000; ++i) {
    const double t = 0.004 * i;
    const double a = W * t;
    const Vec3 p(r * std::cos(a), r * std::sin(a), 0.0);
    // camera z towards the centre, camera y along world -z, x = y cross z
    const Vec3 z = -p.normalized(), y(0, 0, -1), x = y.cross(z);
    Mat3 R;
    R.col(0) = x, R.col(1) = y, R.col(2) = z;
    PoseSample s;
    s.t = t;
    s.position = p;
    s.orientation = Eigen::Quaterniond(R);
    poses.push_back(s);
  }
  GtVelocityEstimator est(poses);
  // world velocity r W (-sin a, cos a, 0); camera x = y cross z = (0,0,-1) x (-cos a, -sin a, 0)
  // = (-sin a, cos a, 0): the velocity is +r W along camera x.
  const Vec3 expect(r * W, 0.0, 0.0);
  for (double t0 : {1.0, 5.5, 10.0}) {
    const GtVelocity g = est.window(t0, t0 + 0.1);
    ASSERT_TRUE(g.ok());
    EXPECT_LT((g.v_cam - expect).norm() / expect.norm(), 1e-3) << g.v_cam.transpose();
  }
  const GtVelocity single = est.at(3.0);
  EXPECT_LT((single.v_cam - expect).norm() / expect.norm(), 1e-3);
}

TEST(EvalGtVelocity, StatusesOutsideAndSparse) {
  std::vector<PoseSample> poses;
  for (int i = 0; i < 10; ++i) {
    PoseSample p;
    p.t = 0.1 * i;
    p.position = Vec3(i, 0, 0);
    poses.push_back(p);
  }
  GtVelocityEstimator est(poses);
  EXPECT_EQ(est.window(2.0, 2.1).status, GtStatus::NotCovered);
  EXPECT_EQ(est.window(0.3, 0.2).status, GtStatus::InvalidWindow);
  EXPECT_EQ(est.at(0.45).status, GtStatus::TooFewPoses);  // 10 Hz poses, +-50 ms neighbourhood
  GtVelocityOptions wide;
  wide.half_width = 0.3;
  GtVelocityEstimator est2(poses, Eigen::Matrix4d::Identity(), wide);
  const GtVelocity g = est2.at(0.45);
  ASSERT_TRUE(g.ok());
  EXPECT_NEAR(g.v_cam.x(), 10.0, 1e-9);  // 1 m per 0.1 s, linear: exact
  GtVelocityOptions bad;
  bad.degree = 0;
  EXPECT_THROW(GtVelocityEstimator(poses, Eigen::Matrix4d::Identity(), bad), std::invalid_argument);
}
