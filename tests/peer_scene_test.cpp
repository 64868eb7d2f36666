// The peer scene with an accelerating camera (PeerSceneOptions::acceleration)
// and what a constant-velocity solver makes of it (docs/accuracy.md, "A
// camera that accelerates").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "celc/pipeline/run_config.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"

using namespace celc;

namespace {

double medianOf(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return x[x.size() / 2];
}

}  // namespace

// Noise-free events lie on their segment seen from p(t) = tau v + tau^2 a / 2
// (reference frame), and not on it seen from tau v alone.
TEST(PeerScene, AcceleratingCameraSeesItsSegments) {
  PeerSceneOptions o;
  o.event_noise_px = 0.0;
  o.acceleration = 2.0;
  std::mt19937_64 rng(5);
  const PeerSceneTrial tr = generatePeerScene(o, rng);
  ASSERT_TRUE(tr.ok) << tr.message;
  EXPECT_NEAR(tr.true_acceleration.norm(), 2.0, 1e-12);
  const Vec3 v = tr.true_direction * o.speed;
  double worst_accelerating = 0.0, worst_constant = 0.0;
  for (size_t c = 0; c < tr.segments.size(); ++c) {
    const auto& cl = tr.truth.clusters[c];
    for (size_t k = 0; k < cl.size(); ++k) {
      const double tau = cl.times[k] - o.t_ref;
      const Vec3 ray = tr.true_motion.rotation(cl.times[k]) * cl.bearings[k].normalized();
      // Sine of the angle between the ray and the plane of the camera centre and the segment.
      auto offPlane = [&](const Vec3& p) {
        const Vec3 n = (tr.segments[c][0] - p).cross(tr.segments[c][1] - p).normalized();
        return std::abs(ray.dot(n));
      };
      worst_accelerating = std::max(worst_accelerating, offPlane(tau * v + 0.5 * tau * tau * tr.true_acceleration));
      worst_constant = std::max(worst_constant, offPlane(tau * v));
    }
  }
  EXPECT_LT(worst_accelerating, 1e-9);
  // 2 m/s^2 over 0.25 s moves the camera by 6 cm: about 1 deg at 2-6 m.
  EXPECT_GT(worst_constant, 1e-3);
}

// The constant-velocity bias depends on rho = |a| Z / (2 V^2), not on the
// window's length: at rho = 0.3 celc_ml's median error is about the same
// for T = 0.5 s and 1 s (measured 9.5 and 10.1 deg on 100 trials), and far
// above its error without acceleration at T = 1 s (0.25 deg).
TEST(PeerScene, ConstantVelocityBiasFollowsTheAccelerationRatio) {
  const RunConfig defaults;
  auto medianDeg = [&](double T, double rho) {
    PeerSceneOptions o;
    o.speed = 2.0;
    o.duration = T;
    o.event_noise_px = 0.5;
    o.acceleration = rho * 2.0 * o.speed * o.speed / 4.0;  // Z = 4 m, the depths' middle
    std::mt19937_64 rng(31);
    std::vector<double> phi;
    for (int t = 0; t < 30; ++t) {
      const PeerSceneTrial tr = generatePeerScene(o, rng);
      if (!tr.ok) continue;
      const SolverResult r = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, defaults.solver,
                                          SampleSeeds{defaults.seed, defaults.seed})[0];
      phi.push_back(r.ok() ? angleBetweenSignAgnostic(r.v, tr.true_direction) * 180.0 / M_PI : 90.0);
    }
    EXPECT_GE(phi.size(), 28u);
    return medianOf(phi);
  };
  const double half = medianDeg(0.5, 0.3), whole = medianDeg(1.0, 0.3), none = medianDeg(1.0, 0.0);
  EXPECT_GT(half, 5.0);
  EXPECT_LT(half, 16.0);
  EXPECT_LT(std::max(half, whole) / std::min(half, whole), 1.5);
  EXPECT_LT(none, 1.0);
}
