// The Monte-Carlo study engine (pipeline/study_engine.hpp).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>

#include "celc/pipeline/study_engine.hpp"

using namespace celc;

// One derivation for every study: seed_seq over (seed low, seed high, key..., trial).
TEST(StudyEngine, TrialRngIsTheSeedSequenceOfSeedKeyAndTrial) {
  const std::uint64_t seed = 0x123456789abcdefULL;
  std::seed_seq two{0x89abcdefu, 0x1234567u, 77u, 3u, 5u};
  std::mt19937_64 expected_two(two);
  std::mt19937_64 got_two = trialRng(seed, {77u, 3u}, 5);
  EXPECT_EQ(got_two(), expected_two());
  std::seed_seq one{0x89abcdefu, 0x1234567u, 4242u, 9u};
  std::mt19937_64 expected_one(one);
  std::mt19937_64 got_one = trialRng(seed, {4242u}, 9);
  EXPECT_EQ(got_one(), expected_one());
}

// Every trial runs once with its own generator: the outcomes do not depend on
// the thread count; missing method outcomes count as not ok.
TEST(StudyEngine, OutcomesIndependentOfThreads) {
  StudyPlan plan;
  plan.cells = {{1u, 0u}, {1u, 1u}, {2u}};
  plan.trials = 17;
  plan.methods = 2;
  plan.seed = 5;
  auto trial = [](std::size_t cell, int t, std::mt19937_64& rng) {
    TrialOutcome o;
    MethodOutcome m;
    m.ok = true;
    m.phi = static_cast<double>(rng() % 1000) + 1000.0 * static_cast<double>(cell) + 1e-3 * t;
    o.methods.push_back(m);  // the second method left out
    o.reference = cell == 2 ? NAN : 1.0;
    return o;
  };
  std::atomic<int> last_total{0}, calls{0};
  const StudyOutcomes a = runStudy(plan, trial);
  plan.threads = 3;
  const StudyOutcomes b = runStudy(plan, trial, [&](int, int total) {
    last_total = total;
    ++calls;  // from worker threads
  });
  EXPECT_EQ(calls.load(), 3 * 17);
  EXPECT_EQ(last_total.load(), 3 * 17);
  for (std::size_t c = 0; c < 3; ++c) {
    const auto ma = a.methodOutcomes(c, 0), mb = b.methodOutcomes(c, 0);
    ASSERT_EQ(ma.size(), 17u);
    for (std::size_t t = 0; t < ma.size(); ++t) EXPECT_EQ(ma[t].phi, mb[t].phi);
    for (const MethodOutcome& o : a.methodOutcomes(c, 1)) EXPECT_FALSE(o.ok);
    EXPECT_EQ(std::isnan(a.trial(c, 0).reference), c == 2);
  }
}

TEST(StudyEngine, ScoresOnlyOkResults) {
  SolverResult ok, failed;
  ok.status = SolveStatus::Ok;
  ok.v = Vec3(0, 0, -1);
  ok.time_us = 12.0;
  failed.status = SolveStatus::Degenerate;
  const auto s = scoreResults({ok, failed}, Vec3(0, 0, 1));
  ASSERT_EQ(s.size(), 2u);
  EXPECT_TRUE(s[0].ok);
  EXPECT_NEAR(s[0].eps, 2.0, 1e-12);
  EXPECT_NEAR(s[0].phi, M_PI, 1e-12);
  EXPECT_NEAR(s[0].phi_sign_agnostic, 0.0, 1e-12);
  EXPECT_EQ(s[0].time_us, 12.0);
  EXPECT_FALSE(s[1].ok);
}
