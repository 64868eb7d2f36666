// CELC, CE3LC and the refinements on the paper's synthetic scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "celc/geometry/so3.hpp"
#include "celc/sim/line_scene.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"
#include "solver/constraint_rows.hpp"
#include "solver/refine_costs.hpp"

using namespace celc;

namespace {

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

struct MethodStats {
  int ok = 0, degenerate = 0, sign_right = 0;
  double phi_sum = 0.0;
  double meanPhi() const { return ok ? phi_sum / ok : NAN; }
};

// Runs `trials` scenes and accumulates per-method statistics.
std::vector<MethodStats> runTrials(const LineSceneOptions& o, int trials, std::uint64_t seed,
                                   const std::vector<Method>& methods,
                                   const SolverOptions& so = SolverOptions::paper()) {
  std::mt19937_64 rng(seed);
  std::vector<MethodStats> stats(methods.size());
  for (int i = 0; i < trials; ++i) {
    const LineSceneTrial tr = generateLineScene(o, rng);
    const auto res = solveMethods(tr.observations, tr.given_motion, methods, so);
    for (size_t m = 0; m < methods.size(); ++m) {
      if (res[m].status == SolveStatus::Degenerate) ++stats[m].degenerate;
      if (!res[m].ok()) continue;
      ++stats[m].ok;
      const double phi = angleBetween(res[m].v, tr.true_direction);
      stats[m].phi_sum += phi;
      if (phi < M_PI / 2) ++stats[m].sign_right;
    }
  }
  return stats;
}

LineSceneOptions noiseFree() {
  LineSceneOptions o;
  o.event_noise_px = 0.0;
  o.line_noise_px = 0.0;
  return o;
}

}  // namespace

// Exact data: every solver recovers v to numerical precision, with random
// twists (rotations up to 3 rad about the optical axis, 1.2 rad about any axis).
TEST(Solvers, NoiseFreeRecoversVelocityBothMotionModels) {
  std::mt19937_64 rng(11);
  for (auto model : {MotionModelKind::ConstantTwist, MotionModelKind::GyroIntegrated}) {
    for (int i = 0; i < 20; ++i) {
      LineSceneOptions o = noiseFree();
      o.motion = model;
      o.velocity = randomUnit(rng) * (0.5 + 2.0 * (i % 4));
      o.velocity.z() *= 0.3;  // keep the scene in front over the window
      o.duration = 0.3 + 0.1 * (i % 10);
      const double angle = (i % 3 == 0) ? 3.0 : 1.2;
      o.omega = (i % 3 == 0 ? Vec3::UnitZ() : randomUnit(rng)) * angle / o.duration;
      const LineSceneTrial tr = generateLineScene(o, rng);
      const auto res = solveMethods(tr.observations, tr.given_motion, paperMethods(), SolverOptions::paper());
      for (size_t m = 0; m < res.size(); ++m) {
        ASSERT_TRUE(res[m].ok()) << toString(paperMethods()[m]) << " " << res[m].message;
        // npt models P(t) = tau I: exact for a reference-frame velocity only
        // (the peer scene, solver_npt_test.cpp, which also bounds its error
        // under a body-frame velocity, the model of both kinds here).
        if (paperMethods()[m] == Method::Npt) continue;
        EXPECT_LT(angleBetween(res[m].v, tr.true_direction), 1e-6)
            << toString(paperMethods()[m]) << " model " << toString(model) << " trial " << i;
      }
    }
  }
}

// A camera turning fast at a constant rate with a constant body-frame velocity
// (the paper's model, and what a hand-held camera does over a short window),
// solved with the gyro-integrated model built from 1 kHz samples of that rate:
// the same exact answer as with the constant twist. (A model whose velocity is
// constant in the reference frame, P = tau I, is off by about 0.8 rad here.)
TEST(Solvers, GyroIntegratedModelIsBodyFrameLikeTheTwist) {
  std::mt19937_64 rng(5);
  const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::CelcMl, Method::Ce3lc};
  for (int i = 0; i < 10; ++i) {
    LineSceneOptions o = noiseFree();
    o.velocity = randomUnit(rng) * 1.5;
    o.velocity.z() = std::abs(o.velocity.z()) + 0.5;
    o.duration = 0.3;
    o.omega = randomUnit(rng) * 2.0;  // 0.6 rad over the window
    const LineSceneTrial tr = generateLineScene(o, rng);
    std::vector<double> times;
    std::vector<Vec3> rates;
    const double t0 = tr.given_motion.referenceTime();
    for (int k = -5; k <= 305; ++k) {
      times.push_back(t0 + 1e-3 * k);
      rates.push_back(o.omega);
    }
    const MotionModel gyro = MotionModel::gyroIntegrated(times, rates, t0);
    const auto res = solveMethods(tr.observations, gyro, methods, SolverOptions::paper());
    for (size_t m = 0; m < res.size(); ++m) {
      ASSERT_TRUE(res[m].ok()) << toString(methods[m]) << " " << res[m].message;
      EXPECT_LT(angleBetween(res[m].v, tr.true_direction), 1e-6) << toString(methods[m]) << " trial " << i;
    }
  }
}

// The paper's default setting (Sec. 5.1): 2 px event and line noise, 5 lines.
TEST(Solvers, PaperDefaultOrdering) {
  LineSceneOptions o;  // defaults are the paper's
  const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::CelcMl, Method::Ce3lc};
  const auto s = runTrials(o, 200, 2021, methods);
  for (size_t m = 0; m < methods.size(); ++m) {
    EXPECT_GE(s[m].ok, 190) << toString(methods[m]);
    // Sign by cheirality right in >= 95% of the trials that give a velocity.
    EXPECT_GE(s[m].sign_right, 0.95 * s[m].ok) << toString(methods[m]);
  }
  EXPECT_LE(s[1].meanPhi(), s[0].meanPhi());  // celc_opt <= celc
  EXPECT_LT(s[0].meanPhi(), s[3].meanPhi());  // celc < ce3lc
  EXPECT_LT(s[2].meanPhi(), s[1].meanPhi());  // joint ML beats v alone
  // Absolute level (measured 0.16 rad for celc): guards against regressions.
  EXPECT_LT(s[0].meanPhi(), 0.25);
}

TEST(Solvers, ErrorGrowsWithEventNoise) {
  double previous = 0.0;
  for (double noise : {0.5, 2.0, 4.0}) {
    LineSceneOptions o;
    o.event_noise_px = noise;
    const double phi = runTrials(o, 100, 7, {Method::Celc})[0].meanPhi();
    EXPECT_GT(phi, previous) << "noise " << noise;
    previous = phi;
  }
}

TEST(Solvers, ErrorFallsWithNumberOfLines) {
  double previous = M_PI;
  for (int lines : {2, 5, 10}) {
    LineSceneOptions o;
    o.n_lines = lines;
    const double phi = runTrials(o, 100, 8, {Method::CelcOpt})[0].meanPhi();
    EXPECT_LT(phi, previous) << lines << " lines";
    previous = phi;
  }
}

TEST(Solvers, SignRightOnNoiseFreeData) {
  const auto s = runTrials(noiseFree(), 200, 5, {Method::Celc, Method::Ce3lc});
  for (const auto& m : s) EXPECT_GE(m.sign_right, 0.99 * 200);
}

// Where the direction is weakly determined (the peers' scene at V = 2 m/s,
// 1 px: the two smallest generalised eigenvalues within ~10%), the IRLS's
// fixed-point step overshot into a 2-cycle 9-15 deg wide and ran all its
// iterations, its answer set by their parity: 5 of these 20 fixed-seed
// trials ran to max_iterations. With the relaxed step at most one may (a
// slow creep along a valley whose eigenvalues are within 3% can still use
// them all; measured: one).
TEST(Solvers, LinearIrlsSettlesWhereTheDirectionIsWeak) {
  PeerSceneOptions o;
  std::mt19937_64 rng(42);
  const LinearOptions opt = SolverOptions::paper().linear;
  int trials = 0, at_limit = 0;
  double phi_sum = 0.0;
  while (trials < 20) {
    const PeerSceneTrial tr = generatePeerScene(o, rng);
    if (!tr.ok) continue;
    ++trials;
    const SolverResult r = solveCelcLinear(tr.observations, tr.given_motion, opt);
    ASSERT_TRUE(r.ok()) << r.message;
    at_limit += r.iterations >= opt.max_iterations;
    phi_sum += std::acos(std::min(1.0, std::abs(tr.true_direction.dot(r.v.normalized()))));
  }
  EXPECT_LE(at_limit, 1);
  // Still the estimator it was: the mean sign-agnostic error stays near the
  // study's figures for celc in this cell (median 5 deg, docs/accuracy.md).
  EXPECT_LT(phi_sum / trials * 180.0 / M_PI, 15.0);
}

// The Tukey stage (tukey_k > 0, `celc run`'s 3) continues from the Huber
// fixed point at that point's robust scale, and lengthens its step while
// successive steps shrink in one direction (the fixed-point map's linear
// convergence). On 16 trials of the peers' scene with 5 x 20 events it adds
// 5.6 passes on average (8.0 when it re-estimated the scale at every pass
// and only ever halved its step); the estimator stays as accurate.
TEST(Solvers, LinearTukeyStageAddsFewPasses) {
  PeerSceneOptions o;
  o.events_per_line = 20;
  std::mt19937_64 rng(42);
  LinearOptions huber = SolverOptions::paper().linear, tukey = huber;
  tukey.tukey_k = 3.0;
  int trials = 0, extra = 0;
  double phi_huber = 0.0, phi_tukey = 0.0;
  auto phi = [](const PeerSceneTrial& tr, const SolverResult& r) {
    return std::acos(std::min(1.0, std::abs(tr.true_direction.dot(r.v.normalized()))));
  };
  while (trials < 16) {
    const PeerSceneTrial tr = generatePeerScene(o, rng);
    if (!tr.ok) continue;
    ++trials;
    const SolverResult h = solveCelcLinear(tr.observations, tr.given_motion, huber);
    const SolverResult t = solveCelcLinear(tr.observations, tr.given_motion, tukey);
    ASSERT_TRUE(h.ok() && t.ok()) << h.message << t.message;
    extra += t.iterations - h.iterations;
    phi_huber += phi(tr, h);
    phi_tukey += phi(tr, t);
  }
  EXPECT_LE(extra, 6.5 * trials);
  EXPECT_LT(phi_tukey, 1.25 * phi_huber);
}

TEST(Degeneracy, ZeroVelocityIsDegenerate) {
  LineSceneOptions o;
  o.velocity = Vec3::Zero();
  const auto s = runTrials(o, 50, 3, paperMethods());
  for (const auto& m : s) EXPECT_EQ(m.degenerate, 50);
  const auto s0 = runTrials(noiseFree(), 1, 3, paperMethods());  // sanity: the same scene moving is fine
  for (const auto& m : s0) EXPECT_EQ(m.ok, 1);
  LineSceneOptions nf = noiseFree();
  nf.velocity = Vec3::Zero();
  for (const auto& m : runTrials(nf, 20, 4, paperMethods())) EXPECT_EQ(m.degenerate, 20);
}

TEST(Degeneracy, ParallelLinesWithMotionAlongThem) {
  LineSceneOptions o;
  o.event_noise_px = 0.5;
  o.line_noise_px = 0.5;
  const Vec3 d(1.0, 0.0, 0.0);
  for (int i = 0; i < 5; ++i) {
    const Vec3 p(-1.0, -1.5 + 0.7 * i, 3.0 + 0.6 * i);
    o.fixed_segments.push_back({p, p + 2.0 * d});
  }
  o.velocity = 2.0 * d;
  // Rotation about d keeps the body-frame velocity along d in the world too
  // (with w about z the motion would turn away from the lines).
  o.omega = 0.8 * d;
  const auto s = runTrials(o, 20, 9, paperMethods());
  for (size_t m = 0; m < s.size(); ++m) EXPECT_EQ(s[m].degenerate, 20) << toString(paperMethods()[m]);
}

TEST(Degeneracy, OneClusterIsDegenerate) {
  LineSceneOptions o;
  o.n_lines = 1;
  std::mt19937_64 rng(1);
  const auto tr = generateLineScene(o, rng);
  for (const auto& r : solveMethods(tr.observations, tr.given_motion, paperMethods(), SolverOptions::paper())) {
    EXPECT_EQ(r.status, SolveStatus::Degenerate);
    EXPECT_EQ(r.degeneracy, Degeneracy::TooFewClusters);
  }
}

TEST(Solvers, BadInputGivesStatusNotCrash) {
  std::mt19937_64 rng(2);
  const auto tr = generateLineScene(LineSceneOptions{}, rng);
  WindowObservations empty;
  for (const auto& r : solveMethods(empty, tr.given_motion, paperMethods(), SolverOptions::paper()))
    EXPECT_EQ(r.status, SolveStatus::Degenerate);
  WindowObservations bad_focal = tr.observations;
  bad_focal.focal_px = 0.0;
  EXPECT_EQ(solveCelcLinear(bad_focal, tr.given_motion, SolverOptions::paper().linear).status, SolveStatus::InvalidInput);
  // NaN events are skipped, NaN lines make a cluster unusable: still a result.
  WindowObservations nan = tr.observations;
  for (size_t k = 0; k < nan.clusters[0].size(); k += 3)
    nan.clusters[0].bearings[k].x() = std::numeric_limits<double>::quiet_NaN();
  nan.clusters[1].l1.normal.setConstant(std::numeric_limits<double>::quiet_NaN());
  for (const auto& r : solveMethods(nan, tr.given_motion, paperMethods(), SolverOptions::paper())) {
    EXPECT_TRUE(r.ok()) << r.message;
    EXPECT_TRUE(r.v.allFinite());
  }
  const auto nan_motion = MotionModel::constantTwist(Vec3::Constant(NAN), 0.0);
  EXPECT_EQ(solveCelcLinear(tr.observations, nan_motion, SolverOptions::paper().linear).status, SolveStatus::InvalidInput);
  LinearOptions bad = SolverOptions::paper().linear;
  bad.huber_k = -1.0;
  EXPECT_EQ(solveCelcLinear(tr.observations, tr.given_motion, bad).status,
            SolveStatus::InvalidInput);
}

// The CELC row: a noise-free event gives a.v = 0 at the true v, and a.v/|N v|
// is its distance to the transferred line.
TEST(ConstraintRows, ResidualIsPointToLineDistance) {
  std::mt19937_64 rng(4);
  LineSceneOptions o = noiseFree();
  const auto tr = generateLineScene(o, rng);
  const auto& c = tr.observations.clusters[0];
  const auto frame = makeClusterFrame(c, tr.true_motion);
  for (size_t k = 0; k < c.size(); k += 17) {
    const auto row = detail::celcRow(frame, tr.true_motion, c.times[k], c.bearings[k]);
    EXPECT_NEAR(row.a.dot(tr.true_direction) / (row.N * tr.true_direction).norm(), 0.0, 1e-12);
    // Move the event by 0.01 (normalised) across the line: residual 0.01.
    const Vec3 l = tr.true_motion.rotation(c.times[k]).transpose() *
                   detail::transferMatrix(frame, tr.true_motion, c.times[k]) * tr.true_direction;
    const Vec2 nrm = l.head<2>().normalized();
    const Vec3 moved = c.bearings[k] + Vec3(nrm.x(), nrm.y(), 0.0) * 0.01;
    const auto row2 = detail::celcRow(frame, tr.true_motion, c.times[k], moved);
    EXPECT_NEAR(std::abs(row2.a.dot(tr.true_direction)) / (row2.N * tr.true_direction).norm(),
                0.01, 1e-9);
  }
}

// The refinement's analytic gradients (w.r.t. v, m1, m3) against central
// differences, and its residual against the linear stage's a.v / |N v|.
TEST(Refinement, AnalyticJacobianMatchesNumeric) {
  std::mt19937_64 rng(6);
  LineSceneOptions o;
  const auto tr = generateLineScene(o, rng);
  const auto& c = tr.observations.clusters[0];
  const auto& motion = tr.given_motion;
  const auto frame = makeClusterFrame(c, motion);
  const double focal = tr.observations.focal_px;
  for (size_t k = 0; k < c.size(); k += 23) {
    const Mat3 Rk = motion.rotation(c.times[k]), Pk = motion.positionMatrix(c.times[k]);
    const EventTerm e{Rk * c.bearings[k], Rk.transpose().topRows<2>(), frame.Pe - Pk,
                              frame.Ps - Pk};
    const Vec3 v = (tr.true_direction + 0.2 * randomUnit(rng)).normalized();
    Vec3 gv, g1, g3;
    const double d = eventDistance(e, v, frame.m1, frame.m3, focal, &gv, &g1, &g3);
    const auto row = detail::celcRow(frame, motion, c.times[k], c.bearings[k]);
    EXPECT_NEAR(d, focal * row.a.dot(v) / (row.N * v).norm(), 1e-9 * std::max(1.0, std::abs(d)));
    const double h = 1e-7;
    for (int j = 0; j < 3; ++j) {
      const Vec3 dh = Vec3::Unit(j) * h;
      const double nv = (eventDistance(e, v + dh, frame.m1, frame.m3, focal, nullptr, nullptr, nullptr) -
                         eventDistance(e, v - dh, frame.m1, frame.m3, focal, nullptr, nullptr, nullptr)) / (2 * h);
      const double n1 = (eventDistance(e, v, frame.m1 + dh, frame.m3, focal, nullptr, nullptr, nullptr) -
                         eventDistance(e, v, frame.m1 - dh, frame.m3, focal, nullptr, nullptr, nullptr)) / (2 * h);
      const double n3 = (eventDistance(e, v, frame.m1, frame.m3 + dh, focal, nullptr, nullptr, nullptr) -
                         eventDistance(e, v, frame.m1, frame.m3 - dh, focal, nullptr, nullptr, nullptr)) / (2 * h);
      EXPECT_NEAR(gv(j), nv, 1e-4 * std::max(1.0, std::abs(nv)));
      EXPECT_NEAR(g1(j), n1, 1e-4 * std::max(1.0, std::abs(n1)));
      EXPECT_NEAR(g3(j), n3, 1e-4 * std::max(1.0, std::abs(n3)));
    }
  }
  // The square-rooted Huber: r^2 = rho(d^2), slope = dr/dd.
  for (double d : {-5.0, -1.0, 0.3, 1.5, 7.0}) {
    double slope = 0.0;
    const double r = detail::sqrtHuber(d, 1.5, &slope);
    const double rho = std::abs(d) <= 1.5 ? d * d : 2 * 1.5 * std::abs(d) - 1.5 * 1.5;
    EXPECT_NEAR(r * r, rho, 1e-12);
    double s2 = 0.0;
    const double numeric = (detail::sqrtHuber(d + 1e-7, 1.5, &s2) - detail::sqrtHuber(d - 1e-7, 1.5, &s2)) / 2e-7;
    EXPECT_NEAR(slope, numeric, 1e-6);
  }
  // The square-rooted Cauchy: r^2 = c^2 log(1 + d^2 / c^2), slope = dr/dd.
  for (double d : {-5.0, -1.0, -1e-8, 0.3, 1.5, 7.0}) {
    double slope = 0.0;
    const double r = detail::sqrtCauchy(d, 0.8, &slope);
    EXPECT_NEAR(r * r, 0.64 * std::log1p(d * d / 0.64), 1e-12);
    EXPECT_EQ(r < 0, d < 0);
    double s2 = 0.0;
    const double numeric = (detail::sqrtCauchy(d + 1e-7, 0.8, &s2) - detail::sqrtCauchy(d - 1e-7, 0.8, &s2)) / 2e-7;
    EXPECT_NEAR(slope, numeric, 1e-6);
  }
  // The square-rooted Tukey biweight: r^2 = (c^2 / 3)(1 - (1 - d^2 / c^2)^3)
  // inside c, c^2 / 3 beyond with slope 0 (no pull), slope = dr/dd.
  for (double d : {-5.0, -1.0, -1e-8, 0.3, 1.5, 2.9, 7.0}) {
    const double c = 3.0;
    double slope = 0.0;
    const double r = detail::sqrtTukey(d, c, &slope);
    const double u = 1.0 - std::min(1.0, d * d / (c * c));
    EXPECT_NEAR(r * r, c * c / 3.0 * (1.0 - u * u * u), 1e-12);
    EXPECT_EQ(r < 0, d < 0);
    double s2 = 0.0;
    const double numeric = (detail::sqrtTukey(d + 1e-7, c, &s2) - detail::sqrtTukey(d - 1e-7, c, &s2)) / 2e-7;
    EXPECT_NEAR(slope, numeric, 1e-6);
    if (std::abs(d) >= c) {
      EXPECT_EQ(slope, 0.0);
    }
  }
}

// The one loss type: its two forms agree on the cost (r^2 = rho(d)), and
// the last refinement's loss follows its keys (cauchy_scale 0: none;
// tukey_scale > 0: Tukey's; else Cauchy's; none without a tail).
TEST(RobustLoss, FormsAgreeAndTheLastStageFollowsItsKeys) {
  using detail::RobustLoss;
  const RobustLoss losses[] = {RobustLoss{}, RobustLoss::huber(1.5), RobustLoss::cauchy(0.8), RobustLoss::tukey(3.0)};
  for (const RobustLoss& loss : losses)
    for (double d : {-5.0, -1.0, 0.3, 1.5, 2.9, 7.0}) {
      double slope = 0.0;
      const double r = loss.sqrtResidual(d, &slope);
      EXPECT_NEAR(r * r, loss.rho(d), 1e-12) << static_cast<int>(loss.type) << " " << d;
    }
  const auto px = [](double k) { return 2.0 * k; };  // a robust scale of 2 px, with a tail
  const auto no_tail = [](double) { return 0.0; };
  EXPECT_EQ(detail::redescendingLoss(0.0, 3.0, px).type, RobustLoss::Type::None);
  EXPECT_EQ(detail::redescendingLoss(2.4, 0.0, no_tail).type, RobustLoss::Type::None);
  const RobustLoss cauchy = detail::redescendingLoss(2.4, 0.0, px);
  EXPECT_EQ(cauchy.type, RobustLoss::Type::Cauchy);
  EXPECT_EQ(cauchy.scale, 4.8);
  const RobustLoss tukey = detail::redescendingLoss(2.4, 3.0, px);
  EXPECT_EQ(tukey.type, RobustLoss::Type::Tukey);
  EXPECT_EQ(tukey.scale, 6.0);
}

TEST(MethodNames, RoundTrip) {
  for (Method m : allMethods()) EXPECT_EQ(parseMethod(toString(m)), m);
  EXPECT_EQ(parseMethodList("celc, ce3lc").size(), 2u);
  EXPECT_EQ(parseMethod("npt"), Method::Npt);
  EXPECT_EQ(parseMethod("celc_acc"), Method::CelcAcc);
  // "all" is every method; the default leaves celc_acc out (asked for by name).
  EXPECT_EQ(parseMethodList("all").size(), allMethods().size());
  EXPECT_EQ(allMethods().size(), paperMethods().size() + 1);
  EXPECT_THROW(parseMethod("npt2"), std::invalid_argument);
  EXPECT_THROW(parseMethodList(""), std::invalid_argument);
}
