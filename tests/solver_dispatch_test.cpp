// The dispatcher (solveMethods) against the methods run one by one: the
// clusters' frames it computes once per window and shares with every method
// and sign test give the same results as each method's own frames, and the
// per-window seeds passed as arguments the same as seeds set in the options;
// the estimates kept in a SharedSolves store those of one call.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "celc/sim/line_scene.hpp"
#include "celc/solver/npt.hpp"
#include "celc/solver/solver.hpp"
#include "solver/constraint_rows.hpp"
#include "solver/sign_test.hpp"

using namespace celc;

namespace {

void expectSameResult(const SolverResult& a, const SolverResult& b, const char* what, int trial) {
  EXPECT_EQ(a.status, b.status) << what << ", trial " << trial;
  EXPECT_EQ(a.v, b.v) << what << ", trial " << trial;
  EXPECT_EQ(a.sigma_min, b.sigma_min) << what << ", trial " << trial;
  EXPECT_EQ(a.sigma_second, b.sigma_second) << what << ", trial " << trial;
  EXPECT_EQ(a.sign_margin, b.sign_margin) << what << ", trial " << trial;
  EXPECT_EQ(a.residual_px, b.residual_px) << what << ", trial " << trial;
  EXPECT_EQ(a.iterations, b.iterations) << what << ", trial " << trial;
  EXPECT_EQ(a.rows_used, b.rows_used) << what << ", trial " << trial;
}

}  // namespace

// celc, ce3lc, celc_opt and npt (sign resolved) from solveMethods are exactly
// the standalone methods' results; the sign test decides the same with the
// window's frames as with frames of its own, for both signs of v.
TEST(SolverDispatch, SharedFramesGiveTheStandaloneResults) {
  std::mt19937_64 rng(23);
  const std::vector<Method> methods{Method::Celc, Method::Ce3lc, Method::CelcOpt, Method::Npt};
  int ok = 0;
  for (int trial = 0; trial < 12; ++trial) {
    LineSceneOptions o;
    o.n_lines = 3 + trial % 4;
    o.events_per_line = 60 + 40 * (trial % 3);
    const LineSceneTrial tr = generateLineScene(o, rng);
    const auto& obs = tr.observations;
    const auto& motion = tr.given_motion;
    SolverOptions so = SolverOptions::paper();
    so.linear.answer_when_observable = false;  // the dispatcher's own step, beyond the standalone methods
    const auto all = solveMethods(obs, motion, methods, so);
    ASSERT_EQ(all.size(), methods.size());
    const SolverResult celc = solveCelcLinear(obs, motion, so.linear);
    expectSameResult(all[0], celc, "celc", trial);
    expectSameResult(all[1], solveCe3lc(obs, motion, so.linear), "ce3lc", trial);
    if (celc.ok()) {
      ++ok;
      SolverResult opt = refineVelocity(obs, motion, celc.v, false, so.refine);
      opt.sigma_min = celc.sigma_min;
      opt.sigma_second = celc.sigma_second;
      opt.sign_margin = celc.sign_margin;
      expectSameResult(all[2], opt, "celc_opt", trial);
    }
    SolverResult npt = solveNpt(obs, motion, so.npt);
    if (npt.ok()) {
      const SignDecision s = resolveSign(obs, motion, npt.v);
      npt.v *= s.sign;
      npt.sign_margin = s.margin * s.sign;
    }
    expectSameResult(all[3], npt, "npt", trial);

    const detail::WindowFrames frames(obs, motion);
    for (const Vec3& v : {tr.true_direction, Vec3(-tr.true_direction)}) {
      const SignDecision with = detail::resolveSign(obs, motion, v, frames);
      const SignDecision without = resolveSign(obs, motion, v);
      EXPECT_EQ(with.sign, without.sign) << "trial " << trial;
      EXPECT_EQ(with.margin, without.margin) << "trial " << trial;
    }
  }
  EXPECT_GT(ok, 8);
}

// Seeds passed per window equal the same seeds set in the options.
TEST(SolverDispatch, SeedsAsArgumentsEqualSeedsInOptions) {
  std::mt19937_64 rng(29);
  LineSceneOptions o;
  o.events_per_line = 400;  // 2000 events: row and event subsets are drawn
  const LineSceneTrial tr = generateLineScene(o, rng);
  SolverOptions in_options = SolverOptions::paper();
  in_options.linear.seed = 7;
  in_options.refine.seed = 9;
  in_options.refine.max_events = 1500;
  SolverOptions defaults = in_options;
  defaults.linear.seed = 1;
  defaults.refine.seed = 1;
  const auto a = solveMethods(tr.observations, tr.given_motion, allMethods(), in_options);
  const auto b = solveMethods(tr.observations, tr.given_motion, allMethods(), defaults, SampleSeeds{7, 9});
  ASSERT_EQ(a.size(), b.size());
  for (size_t m = 0; m < a.size(); ++m) expectSameResult(a[m], b[m], "method", static_cast<int>(m));
}

// SharedSolves: celc_ml solved alone (without uncertainty, as `celc run`'s
// redraw does) and then every method with the same store give every method's
// result of one call without a store, sigma_deg included; celc_ml's is taken
// from the store, not solved again (its time is the first call's).
TEST(SolverDispatch, SharedSolvesGiveTheResultsOfOneCall) {
  std::mt19937_64 rng(31);
  const SolverOptions options;  // `celc run`'s defaults: uncertainty on
  SolverOptions witness = options;
  witness.uncertainty.enabled = false;
  for (int trial = 0; trial < 4; ++trial) {
    LineSceneOptions o;
    o.events_per_line = 400;
    const LineSceneTrial tr = generateLineScene(o, rng);
    const SampleSeeds seeds{3 + static_cast<std::uint64_t>(trial), 5};
    SharedSolves shared;
    const SolverResult first =
        solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, witness, seeds, shared).front();
    const auto with_store = solveMethods(tr.observations, tr.given_motion, allMethods(), options, seeds, shared);
    const auto alone = solveMethods(tr.observations, tr.given_motion, allMethods(), options, seeds);
    ASSERT_EQ(with_store.size(), alone.size());
    for (size_t m = 0; m < alone.size(); ++m) {
      expectSameResult(with_store[m], alone[m], toString(allMethods()[m]).c_str(), trial);
      EXPECT_EQ(with_store[m].sigma_deg, alone[m].sigma_deg) << toString(allMethods()[m]) << ", trial " << trial;
      if (allMethods()[m] == Method::CelcMl) {
        ASSERT_TRUE(first.ok()) << first.message;
        EXPECT_EQ(with_store[m].time_us, first.time_us) << "trial " << trial;
        EXPECT_TRUE(std::isnan(first.sigma_deg) || first.sigma_deg != alone[m].sigma_deg);
      }
    }
  }
}

// The methods side by side on two threads give the results of one thread,
// sigma_deg included, with and without celc_ml already in the store.
TEST(SolverDispatch, MethodsOnTwoThreadsGiveTheResultsOfOne) {
  std::mt19937_64 rng(37);
  const SolverOptions options;
  for (int trial = 0; trial < 4; ++trial) {
    LineSceneOptions o;
    o.events_per_line = 300;
    const LineSceneTrial tr = generateLineScene(o, rng);
    const SampleSeeds seeds{11 + static_cast<std::uint64_t>(trial), 13};
    SharedSolves one, two;
    const auto a = solveMethods(tr.observations, tr.given_motion, allMethods(), options, seeds, one, 1);
    const auto b = solveMethods(tr.observations, tr.given_motion, allMethods(), options, seeds, two, 2);
    SharedSolves stored;
    solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, options, seeds, stored);
    const auto c = solveMethods(tr.observations, tr.given_motion, allMethods(), options, seeds, stored, 2);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.size(), c.size());
    for (size_t m = 0; m < a.size(); ++m) {
      const std::string name = toString(allMethods()[m]);
      expectSameResult(a[m], b[m], name.c_str(), trial);
      expectSameResult(a[m], c[m], name.c_str(), trial);
      EXPECT_EQ(a[m].sigma_deg, b[m].sigma_deg) << name << ", trial " << trial;
      EXPECT_EQ(a[m].sigma_deg, c[m].sigma_deg) << name << ", trial " << trial;
    }
  }
}

// Linear estimates witness only the linear methods (linear_witness_refined
// off): celc_ml asked alone, where no linear witness is formed, gets the
// sigma_deg it gets beside celc and ce3lc.
TEST(SolverDispatch, CelcMlAloneGetsTheSigmaItGetsBesideTheLinearMethods) {
  std::mt19937_64 rng(41);
  const SolverOptions options;
  ASSERT_FALSE(options.uncertainty.linear_witness_refined);
  int finite = 0;
  for (int trial = 0; trial < 6; ++trial) {
    LineSceneOptions o;
    o.events_per_line = 200;
    o.event_noise_px = 1.0 + trial % 3;
    const LineSceneTrial tr = generateLineScene(o, rng);
    const SampleSeeds seeds{17, 19};
    const SolverResult alone =
        solveMethods(tr.observations, tr.given_motion, {Method::CelcMl}, options, seeds).front();
    const auto beside =
        solveMethods(tr.observations, tr.given_motion, {Method::Celc, Method::Ce3lc, Method::CelcMl}, options, seeds);
    expectSameResult(alone, beside[2], "celc_ml", trial);
    EXPECT_EQ(alone.sigma_deg, beside[2].sigma_deg) << "trial " << trial;
    EXPECT_EQ(alone.sigma_rule, beside[2].sigma_rule) << "trial " << trial;
    finite += std::isfinite(alone.sigma_deg) ? 1 : 0;
  }
  EXPECT_GE(finite, 4);
}
