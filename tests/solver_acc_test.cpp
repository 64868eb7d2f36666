// celc_acc: CELC with a constant acceleration (solver/celc_acc.hpp), on the
// peers' scene with a reference-frame acceleration (sim/peer_scene.hpp) and
// on the paper's scene with one (sim/line_scene.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "celc/geometry/so3.hpp"
#include "celc/pipeline/simulation_study.hpp"
#include "celc/sim/line_scene.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"

using namespace celc;

namespace {

constexpr double kPeerMidDepth = 4.0;  // [m], the middle of the peer scene's 2-6 m

/// rho = |a| Z / (2 V^2): the acceleration's share of what fixes v
/// (tests/study/acceleration_study.cpp).
PeerSceneOptions accelerating(double rho, double noise_px) {
  PeerSceneOptions o;
  o.speed = 2.0;
  o.duration = 0.5;
  o.event_noise_px = noise_px;
  o.acceleration = rho * 2.0 * o.speed * o.speed / kPeerMidDepth;
  return o;
}

/// The paper's default scene (2 px event and line noise) with rho as the
/// acceleration sweep sets it (`celc simulate --sweep acceleration`).
LineSceneOptions paperScene(double rho) {
  LineSceneOptions o;
  findSweep("acceleration").apply(o, rho);
  return o;
}

double deg(const Vec3& a, const Vec3& b) { return angleBetween(a, b) * 180.0 / M_PI; }

double median(std::vector<double> x) {
  std::nth_element(x.begin(), x.begin() + static_cast<long>(x.size() / 2), x.end());
  return x[x.size() / 2];
}

const std::vector<Method> kBoth{Method::CelcMl, Method::CelcAcc};

}  // namespace

// Noise-free events of an accelerating camera: v at the reference time and
// the direction of a are exact. The fitted lines l1 / l3 (a motion linear in
// time over their end intervals) are only the start: the joint refinement
// moves them. 0.01 deg is 1.7e-4 rad, far above the refinement's step
// tolerance (1e-8 rad) and rounding.
TEST(CelcAcc, NoiseFreeAcceleratingWindowsAreExact) {
  std::mt19937_64 rng(5);
  std::vector<double> phi_v, phi_a;
  for (int trial = 0; trial < 10; ++trial) {
    const PeerSceneTrial tr = generatePeerScene(accelerating(2.0, 0.0), rng);
    ASSERT_TRUE(tr.ok) << tr.message;
    const auto res = solveMethods(tr.observations, tr.given_motion, {Method::CelcAcc}, SolverOptions::paper());
    ASSERT_TRUE(res[0].ok()) << res[0].message;
    EXPECT_TRUE(res[0].acceleration_seen) << res[0].message;
    EXPECT_EQ(res[0].degeneracy, Degeneracy::None);
    phi_v.push_back(deg(res[0].v, tr.true_direction));
    // a over the speed, in the reference frame.
    phi_a.push_back(deg(res[0].acceleration, tr.true_acceleration));
    EXPECT_NEAR(res[0].acceleration.norm(), tr.true_acceleration.norm() / 2.0, 1e-3 * tr.true_acceleration.norm());
  }
  RecordProperty("median_phi_v_deg", std::to_string(median(phi_v)));
  RecordProperty("median_phi_a_deg", std::to_string(median(phi_a)));
  EXPECT_LT(*std::max_element(phi_v.begin(), phi_v.end()), 0.01);
  EXPECT_LT(*std::max_element(phi_a.begin(), phi_a.end()), 0.01);
}

// The same on the paper's scene (constant twist, v in the body frame, a in
// the reference frame) without event or line noise, at rho = 2 and 20.
TEST(CelcAcc, NoiseFreePaperSceneIsExact) {
  for (double rho : {2.0, 20.0}) {
    std::mt19937_64 rng(11);
    LineSceneOptions o = paperScene(rho);
    o.event_noise_px = o.line_noise_px = 0.0;
    for (int trial = 0; trial < 5; ++trial) {
      const LineSceneTrial tr = generateLineScene(o, rng);
      const auto res = solveMethods(tr.observations, tr.given_motion, {Method::CelcAcc}, SolverOptions::paper());
      ASSERT_TRUE(res[0].ok()) << res[0].message;
      EXPECT_LT(deg(res[0].v, tr.true_direction), 0.01) << "rho " << rho << " trial " << trial;
      EXPECT_LT(deg(res[0].acceleration, tr.true_acceleration), 0.01) << "rho " << rho << " trial " << trial;
    }
  }
}

// Without an acceleration the window shows none (the test's level is
// p = 0.001 per window), and the answer is then celc_ml's, bit for bit.
TEST(CelcAcc, ConstantVelocityIsNotReadAsAcceleration) {
  std::mt19937_64 rng(6);
  int seen = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const PeerSceneTrial tr = generatePeerScene(accelerating(0.0, 0.5), rng);
    ASSERT_TRUE(tr.ok) << tr.message;
    const auto res = solveMethods(tr.observations, tr.given_motion, kBoth, SolverOptions::paper());
    ASSERT_TRUE(res[1].ok()) << res[1].message;
    seen += res[1].acceleration_seen ? 1 : 0;
    if (!res[1].acceleration_seen) {
      EXPECT_EQ(res[1].v, res[0].v);
      EXPECT_NE(res[1].message.find("no acceleration seen"), std::string::npos) << res[1].message;
    }
  }
  EXPECT_LE(seen, 1);
}

// The acceleration sweep's rho = 0 on the paper's scene at its default
// noise: no worse than celc_ml by more than 10% in median phi (where the
// test sees no acceleration the answers are the same; 40 trials, fixed seed).
TEST(CelcAcc, NoWorseThanCelcMlWithoutAcceleration) {
  std::mt19937_64 rng(21);
  std::vector<double> acc, ml;
  for (int trial = 0; trial < 40; ++trial) {
    const LineSceneTrial tr = generateLineScene(paperScene(0.0), rng);
    const auto res = solveMethods(tr.observations, tr.given_motion, kBoth, SolverOptions::paper());
    ml.push_back(res[0].ok() ? deg(res[0].v, tr.true_direction) : 180.0);
    acc.push_back(res[1].ok() ? deg(res[1].v, tr.true_direction) : 180.0);
  }
  RecordProperty("median_phi_celc_acc_deg", std::to_string(median(acc)));
  RecordProperty("median_phi_celc_ml_deg", std::to_string(median(ml)));
  EXPECT_LE(median(acc), 1.1 * median(ml)) << "celc_acc " << median(acc) << " celc_ml " << median(ml);
}

// At rho = 2 with 0.5 px of noise, a constant-velocity solver is biased by
// about 0.66 rad x rho (capped by the geometry); celc_acc is not. The
// measured ratio is about 15 (20 trials); the test asks for the target, 3.
TEST(CelcAcc, BeatsConstantVelocityUnderAcceleration) {
  std::mt19937_64 rng(7);
  std::vector<double> acc, ml;
  for (int trial = 0; trial < 20; ++trial) {
    const PeerSceneTrial tr = generatePeerScene(accelerating(2.0, 0.5), rng);
    ASSERT_TRUE(tr.ok) << tr.message;
    const auto res = solveMethods(tr.observations, tr.given_motion, kBoth, SolverOptions::paper());
    ml.push_back(res[0].ok() ? deg(res[0].v, tr.true_direction) : 180.0);
    acc.push_back(res[1].ok() ? deg(res[1].v, tr.true_direction) : 180.0);
  }
  RecordProperty("median_phi_celc_acc_deg", std::to_string(median(acc)));
  RecordProperty("median_phi_celc_ml_deg", std::to_string(median(ml)));
  EXPECT_LT(3.0 * median(acc), median(ml)) << "celc_acc " << median(acc) << " celc_ml " << median(ml);
}

// Two lines cannot fix an acceleration beside v (acc.min_lines): the answer
// is celc_ml's, status ok, with the reason and the message saying so.
TEST(CelcAcc, TooFewLinesFallBackToConstantVelocity) {
  std::mt19937_64 rng(8);
  LineSceneOptions o = paperScene(5.0);
  o.n_lines = 2;
  const LineSceneTrial tr = generateLineScene(o, rng);
  const auto res = solveMethods(tr.observations, tr.given_motion, kBoth, SolverOptions::paper());
  ASSERT_TRUE(res[0].ok()) << res[0].message;
  ASSERT_TRUE(res[1].ok()) << res[1].message;
  EXPECT_EQ(res[1].degeneracy, Degeneracy::AccelerationUnobservable);
  EXPECT_FALSE(res[1].acceleration_seen);
  EXPECT_EQ(res[1].v, res[0].v);
  EXPECT_NE(res[1].message.find("2 lines"), std::string::npos) << res[1].message;
  EXPECT_NE(res[1].message.find("constant-velocity"), std::string::npos) << res[1].message;
  EXPECT_EQ(toString(res[1].degeneracy), "acceleration_unobservable");
}

// A window too short for its noise to fix a (acc.max_sigma): the same
// fallback, and the message names the observability test. A 0.3 s window
// with 4 px of noise (the paper's scene, rho = 2): about half of its
// windows cannot fix a; with the test off (max_sigma huge) none falls back.
TEST(CelcAcc, ShortNoisyWindowFallsBackToConstantVelocity) {
  LineSceneOptions o = paperScene(2.0);
  o.duration = 0.3;
  o.event_noise_px = 4.0;
  SolverOptions off = SolverOptions::paper();
  off.acc.max_sigma = 1e12;
  int unobservable = 0, unobservable_off = 0, trials = 0;
  std::mt19937_64 rng(9);
  for (int trial = 0; trial < 20; ++trial) {
    const LineSceneTrial tr = generateLineScene(o, rng);
    const auto res = solveMethods(tr.observations, tr.given_motion, kBoth, SolverOptions::paper());
    if (!res[0].ok()) continue;
    ++trials;
    ASSERT_TRUE(res[1].ok()) << res[1].message;
    const auto res_off = solveMethods(tr.observations, tr.given_motion, kBoth, off);
    unobservable_off += res_off[1].degeneracy == Degeneracy::AccelerationUnobservable ? 1 : 0;
    if (res[1].degeneracy != Degeneracy::AccelerationUnobservable) continue;
    ++unobservable;
    EXPECT_EQ(res[1].v, res[0].v);
    EXPECT_FALSE(res[1].acceleration_seen);
    EXPECT_NE(res[1].message.find("not observable"), std::string::npos) << res[1].message;
  }
  ASSERT_GT(trials, 10);
  EXPECT_GE(unobservable, trials / 4) << unobservable << " of " << trials;
  EXPECT_EQ(unobservable_off, 0);
}

// The options check themselves.
TEST(CelcAcc, OptionsValidate) {
  SolverOptions o = SolverOptions::paper();
  EXPECT_EQ(o.validate(), "");
  o.acc.min_lines = 1;
  o.acc.max_sigma = 0.0;
  o.acc.test_chi2 = -1.0;
  const std::string e = o.validate();
  EXPECT_NE(e.find("acc.min_lines"), std::string::npos) << e;
  EXPECT_NE(e.find("acc.max_sigma"), std::string::npos) << e;
  EXPECT_NE(e.find("acc.test_chi2"), std::string::npos) << e;
}

// The acceleration sweep is asked for by name; `all` stays the paper's.
TEST(CelcAcc, AccelerationSweepIsNamedNotInThePapers) {
  const Sweep& s = findSweep("acceleration");
  EXPECT_EQ(s.levels.front(), 0.0);
  EXPECT_EQ(s.levels.back(), 30.0);
  for (const Sweep& p : paperSweeps()) EXPECT_NE(p.name, "acceleration");
  LineSceneOptions o;
  s.apply(o, 2.0);
  // rho = |a| Z / (2 V^2) with Z = 4.5 m (depths 3-6 m), V^2 = 5 m^2/s^2.
  EXPECT_NEAR(o.acceleration, 2.0 * 2.0 * 5.0 / 4.5, 1e-12);
}

namespace {

/// The accelerometer's reading of a peer-scene trial: its true acceleration
/// [m/s^2] turned by `turn` [rad] about an axis normal to it, with sigma [m/s^2].
MeasuredAcceleration measuredAcceleration(const PeerSceneTrial& tr, double turn, double sigma) {
  const Vec3 a = tr.true_acceleration;
  const Vec3 axis = a.cross(Vec3(0.3, -0.5, 0.8)).normalized();
  MeasuredAcceleration m;
  m.valid = true;
  m.a = so3::exp(turn * axis) * a;
  m.sigma = sigma;
  return m;
}

/// The speed in celc_acc's message ("|v| about X m/s"), NaN without it.
double speedInMessage(const std::string& message) {
  const std::size_t at = message.find("|v| about ");
  return at == std::string::npos ? NAN : std::stod(message.substr(at + 10));
}

}  // namespace

// An accelerometer that agrees (its reading within 0.07 m/s^2 of the truth):
// the acceleration is kept as without it, and the speed that fits a to the
// accelerometer's reading is the scene's 2 m/s (within 20%: a is fixed to a
// few per cent at rho = 2 with 0.5 px of noise). One trial of the ten ends
// 84 deg off in a (and 96 deg in v) without the accelerometer: that one the
// accelerometer refuses.
TEST(CelcAcc, AgreeingAccelerometerKeepsTheAccelerationAndGivesTheSpeed) {
  std::mt19937_64 rng(7);
  int kept = 0;
  for (int trial = 0; trial < 10; ++trial) {
    PeerSceneTrial tr = generatePeerScene(accelerating(2.0, 0.5), rng);
    ASSERT_TRUE(tr.ok) << tr.message;
    tr.observations.accelerometer = measuredAcceleration(tr, 0.0, 0.07);
    const auto res = solveMethods(tr.observations, tr.given_motion, {Method::CelcAcc}, SolverOptions::paper());
    ASSERT_TRUE(res[0].ok()) << res[0].message;
    if (!res[0].acceleration_seen) continue;
    ++kept;
    EXPECT_NE(res[0].message.find("the accelerometer agrees"), std::string::npos) << res[0].message;
    EXPECT_NEAR(speedInMessage(res[0].message), 2.0, 0.4) << res[0].message;
  }
  EXPECT_GE(kept, 9);
}

// An accelerometer that contradicts the acceleration the events show (its
// reading turned 90 deg, sigma 0.07 m/s^2 against |a| = 4 m/s^2): no
// accelerating answer is kept, the answer is celc_ml's and says why, and its
// sigma_deg is at least its angle to the refused answer.
TEST(CelcAcc, ContradictingAccelerometerKeepsConstantVelocity) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    PeerSceneTrial tr = generatePeerScene(accelerating(2.0, 0.5), rng);
    ASSERT_TRUE(tr.ok) << tr.message;
    tr.observations.accelerometer = measuredAcceleration(tr, M_PI / 2, 0.07);
    const auto res = solveMethods(tr.observations, tr.given_motion, kBoth, SolverOptions::paper());
    ASSERT_TRUE(res[1].ok()) << res[1].message;
    EXPECT_FALSE(res[1].acceleration_seen) << res[1].message;
    EXPECT_EQ(res[1].v, res[0].v);
    EXPECT_NE(res[1].message.find("the accelerometer contradicts"), std::string::npos) << res[1].message;
    // Neither model explains these events: the angle to the refused answer
    // (celc_ml's bias at rho = 2, tens of degrees) bounds sigma_deg.
    EXPECT_GT(res[1].sigma_floor_deg, 5.0);
    EXPECT_GE(res[1].sigma_deg, res[1].sigma_floor_deg);
    EXPECT_EQ(res[1].sigma_rule, "accelerometer_refused");
  }
}
