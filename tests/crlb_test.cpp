// The Cramér-Rao bound on the velocity direction (eval/crlb.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "celc/eval/crlb.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"

using namespace celc;

namespace {
PeerSceneTrial scene(std::mt19937_64& rng, double speed, double sigma, int lines, int events) {
  PeerSceneOptions o;
  o.speed = speed;
  o.event_noise_px = sigma;
  o.n_lines = lines;
  o.events_per_line = events;
  return generatePeerScene(o, rng);
}
}  // namespace

// Fisher information is sum J^T J / sigma^2: the bound is linear in sigma,
// falls as 1/sqrt(N) when every event is repeated N times, and is zero at sigma 0.
TEST(Crlb, ScalesWithSigmaAndEventCount) {
  std::mt19937_64 rng(1);
  const PeerSceneTrial tr = scene(rng, 2.0, 1.0, 5, 100);
  ASSERT_TRUE(tr.ok);
  const auto b1 = velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, 1.0);
  const auto b2 = velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, 2.0);
  ASSERT_TRUE(b1.ok && b2.ok) << b1.message;
  EXPECT_EQ(b1.events, 500);
  EXPECT_EQ(b1.lines, 5);
  EXPECT_GT(b1.rms_rad, 0.0);
  EXPECT_NEAR(b2.rms_rad, 2.0 * b1.rms_rad, 1e-9 * b1.rms_rad);
  WindowObservations quad = tr.truth;
  for (auto& c : quad.clusters) {
    const auto t = c.times;
    const auto f = c.bearings;
    for (int r = 0; r < 3; ++r) {
      c.times.insert(c.times.end(), t.begin(), t.end());
      c.bearings.insert(c.bearings.end(), f.begin(), f.end());
    }
  }
  const auto b4 = velocityDirectionCrlb(quad, tr.true_motion, tr.true_direction, 1.0);
  EXPECT_NEAR(b4.rms_rad, 0.5 * b1.rms_rad, 1e-6 * b1.rms_rad);
  EXPECT_EQ(velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, 0.0).rms_rad, 0.0);
  // The bound does not depend on the length of the given direction or its sign.
  const auto bs = velocityDirectionCrlb(tr.truth, tr.true_motion, -3.0 * tr.true_direction, 1.0);
  EXPECT_NEAR(bs.rms_rad, b1.rms_rad, 1e-9 * b1.rms_rad);
  // More parallax, tighter bound (same seed: same lines and events).
  std::mt19937_64 rng_a(5), rng_b(5);
  const auto slow = scene(rng_a, 1.0, 1.0, 5, 100), fast = scene(rng_b, 5.0, 1.0, 5, 100);
  double slow_sum = 0, fast_sum = 0;
  slow_sum += velocityDirectionCrlb(slow.truth, slow.true_motion, slow.true_direction, 1.0).rms_rad;
  fast_sum += velocityDirectionCrlb(fast.truth, fast.true_motion, fast.true_direction, 1.0).rms_rad;
  EXPECT_LT(fast_sum, slow_sum);
}

TEST(Crlb, BadInputGivesStatus) {
  std::mt19937_64 rng(2);
  const PeerSceneTrial tr = scene(rng, 2.0, 1.0, 3, 50);
  EXPECT_FALSE(velocityDirectionCrlb(WindowObservations{}, tr.true_motion, tr.true_direction, 1.0).ok);
  EXPECT_FALSE(velocityDirectionCrlb(tr.truth, tr.true_motion, Vec3::Zero(), 1.0).ok);
  EXPECT_FALSE(velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, -1.0).ok);
  EXPECT_FALSE(velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, NAN).ok);
  // One line: its 4 line parameters plus the 2 of v are not all observable
  // from one moving line's events (the direction has one free component).
  WindowObservations one = tr.truth;
  one.clusters.resize(1);
  const auto b = velocityDirectionCrlb(one, tr.true_motion, tr.true_direction, 1.0);
  EXPECT_TRUE(b.ok);
  EXPECT_FALSE(std::isfinite(b.rms_rad)) << b.rms_rad;
}

// The bound against the empirical spread of the maximum-likelihood estimate
// (celc_ml) where ML should be efficient: many events (5 lines x 400), moderate
// noise (0.5 px), strong parallax (V = 5 m/s, ratio 0.625), true rate. Over 60
// fixed-seed trials sqrt(mean phi^2) / sqrt(mean bound^2) must lie in
// [0.75, 1.35]: the RMS of 60 two-dimensional errors has a relative spread of
// about 1/sqrt(120) = 9%, ML's Huber loss (1.5 px = 3 sigma, efficiency > 99%)
// adds nothing visible, and lines fitted from the events only give the start.
TEST(Crlb, MatchesEmpiricalSpreadOfMaximumLikelihood) {
  std::mt19937_64 rng(2024);
  double err_sq = 0.0, bound_sq = 0.0;
  int n = 0;
  SolverOptions so = SolverOptions::paper();
  so.check_parallax = false;
  for (int i = 0; i < 60; ++i) {
    const PeerSceneTrial tr = scene(rng, 5.0, 0.5, 5, 400);
    ASSERT_TRUE(tr.ok);
    const auto b = velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction, 0.5);
    ASSERT_TRUE(b.ok && std::isfinite(b.rms_rad));
    const auto r = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, so)[0];
    if (!r.ok()) continue;
    const double phi = angleBetweenSignAgnostic(r.v, tr.true_direction);
    err_sq += phi * phi;
    bound_sq += b.rms_rad * b.rms_rad;
    ++n;
  }
  EXPECT_GE(n, 57);
  const double ratio = std::sqrt(err_sq / bound_sq);
  EXPECT_GT(ratio, 0.75);
  EXPECT_LT(ratio, 1.35);
}

// celc_ml from extra hemisphere starts (MlOptions::grid_starts): on the
// peer scene at parallax 0.125 (V = 1 m/s), 0.5 px, the single-start joint
// refinement ends in a wrong basin in about a quarter of the trials
// (docs/accuracy.md). With 16 more starts, keeping the lowest robust cost, the
// cost never gets worse and the error spread shrinks. Measured on these 24
// trials: RMS 19.0 -> 10.7 deg with the paper's still 10% lines; with the
// moving-line fit (lines/line_fit.hpp) the single start lands better,
// RMS 14.1 -> 10.75 deg. Asserted: RMS below 0.85x, no more trials above 15 deg.
TEST(MultiStart, JointRefinementEscapesWrongBasins) {
  std::mt19937_64 rng(11);
  // one: the linear and npt starts alone; many: also the line profile's
  // minima (the default) and a lattice of 16. Every start runs to
  // convergence, so that the lowest cost is kept among a superset of starts.
  SolverOptions one = SolverOptions::paper(), many = one;
  one.ml.profile_lattice = 0;
  one.ml.start_iterations = 0;
  many.ml.grid_starts = 16;
  many.ml.start_iterations = 0;
  double ss_one = 0.0, ss_many = 0.0;
  int far_one = 0, far_many = 0, n = 0;
  for (int i = 0; i < 24; ++i) {
    const PeerSceneTrial tr = scene(rng, 1.0, 0.5, 5, 200);
    ASSERT_TRUE(tr.ok) << tr.message;
    const SolverResult a = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, one)[0];
    const SolverResult b = solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, many)[0];
    if (!a.ok() || !b.ok()) continue;
    ++n;
    // The multi-start keeps the single start's end point unless one costs less.
    EXPECT_LE(b.residual_px, a.residual_px * (1.0 + 1e-9)) << "trial " << i;
    const double pa = angleBetweenSignAgnostic(a.v, tr.true_direction) * 180.0 / M_PI;
    const double pb = angleBetweenSignAgnostic(b.v, tr.true_direction) * 180.0 / M_PI;
    ss_one += pa * pa;
    ss_many += pb * pb;
    far_one += pa > 15.0;
    far_many += pb > 15.0;
  }
  ASSERT_GE(n, 20);
  EXPECT_LT(std::sqrt(ss_many / n), 0.85 * std::sqrt(ss_one / n));
  EXPECT_LE(far_many, far_one);
}
