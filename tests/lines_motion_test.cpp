// Boundary lines under motion: labelled events from 3D segments
// (the peer scene: segments in view at both ends of the window, true
// clusters) through the tool's own line fit with its defaults (the moving
// model, given the rotation) and the solvers with theirs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "celc/eval/metrics.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/sim/render_sequence.hpp"
#include "celc/solver/solver.hpp"
#include "lines_motion_scenes.hpp"

namespace celc::test {
namespace {

// Every trial's scene must generate.
Outcome runScenes(const PeerSceneOptions& o, const std::vector<Method>& methods, int n, std::uint64_t seed) {
  return runSceneTrials(o, methods, n, seed, [](const PeerSceneTrial& tr) { EXPECT_TRUE(tr.ok) << tr.message; });
}

const std::vector<Method> kLineMethods{Method::Celc, Method::CelcOpt, Method::Ce3lc};

// Noise-free float pixels: the fitted lines are exact (the moving model is
// exact at constant velocity with the rotation known), so every method that
// uses them is exact up to rounding, still and at 3 rad/s. Measured: at most
// 0.02 deg, where the paper's still 5 ms lines are 7 deg off.
TEST(LinesMotion, NoiseFreeEventsGiveExactVelocityStillAndRotating) {
  for (double omega : {0.0, 3.0}) {
    const Outcome r = runScenes(davis240Scene(4.0, 0.2, omega), kLineMethods, 5, 100);
    ASSERT_EQ(r.trials, 5);
    EXPECT_EQ(r.lines_rejected, 0);
    for (size_t k = 0; k < kLineMethods.size(); ++k)
      for (double d : r.deg[k]) EXPECT_LT(d, 0.5) << toString(kLineMethods[k]) << " at " << omega << " rad/s";
  }
}

// The same kind of events rounded to integer pixels (uniform +-0.5 px), 3 m/s
// over 0.5 s, 2000 events per line, turning at 0.5 rad/s: median within 2 deg
// over 20 scenes. Measured: celc 0.81, celc_opt 0.40, ce3lc 0.80 deg.
TEST(LinesMotion, IntegerPixelsMedianWithinTwoDegrees) {
  PeerSceneOptions o = davis240Scene(3.0, 0.5, 0.5);
  o.integer_pixels = true;
  o.events_per_line = 2000;
  const Outcome r = runScenes(o, kLineMethods, 20, 200);
  ASSERT_EQ(r.trials, 20);
  EXPECT_EQ(r.lines_rejected, 0);
  EXPECT_LT(median(r.deg[0]), 2.0) << "celc";
  EXPECT_LT(median(r.deg[1]), 2.0) << "celc_opt";
}

// Sparse clusters (the peers' scene: 5 lines over 0.5 s, 1 px noise, 2 m/s):
// with 20 and 200 events per line no cluster is rejected (the end intervals
// grow) and every method answers in every trial, except CE3LC: its one middle
// line per cluster leaves it about 60 deg off with 20 events per line, and
// its nullspace test may honestly call such a trial degenerate; with 200 it
// does so in 2 of these 20 trials (measured; its answers there were 38 and
// 82 deg off while its IRLS still cycled, robust_nullspace.cpp).
TEST(LinesMotion, SparseClustersKeepEveryLineAndEveryMethodAnswers) {
  const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::Ce3lc, Method::Npt};
  for (int events : {20, 200}) {
    PeerSceneOptions o;
    o.events_per_line = events;
    const Outcome r = runScenes(o, methods, 20, 300);
    ASSERT_EQ(r.trials, 20);
    EXPECT_EQ(r.lines_rejected, 0) << events << " events per line";
    for (size_t k = 0; k < methods.size(); ++k) {
      const auto not_ok = std::count(r.deg[k].begin(), r.deg[k].end(), 180.0);
      if (methods[k] != Method::Ce3lc) {
        EXPECT_EQ(not_ok, 0) << toString(methods[k]) << " with " << events << " events per line";
      } else if (events == 200) {
        EXPECT_LE(not_ok, 2) << "ce3lc with 200 events per line";
      }
    }
  }
}

// A cluster whose lines could not be fitted stays in the window for npt
// (which needs no fitted lines) and is skipped by the line methods: npt gives
// the answer it gives with the lines, the line methods the answer without
// the cluster.
TEST(LinesMotion, ClusterWithoutLinesServesNptOnly) {
  PeerSceneOptions o;
  std::mt19937_64 rng(17);
  const PeerSceneTrial tr = generatePeerScene(o, rng);
  ASSERT_TRUE(tr.ok) << tr.message;
  ASSERT_EQ(tr.lines_fitted, 5);
  WindowObservations failed = tr.observations, removed = tr.observations;
  failed.clusters[0].has_lines = false;
  removed.clusters.erase(removed.clusters.begin());
  const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::Npt};
  const auto all = solveMethods(tr.observations, tr.given_motion, methods, SolverOptions::paper());
  const auto with_failed = solveMethods(failed, tr.given_motion, methods, SolverOptions::paper());
  const auto without = solveMethods(removed, tr.given_motion, methods, SolverOptions::paper());
  for (size_t k = 0; k < 2; ++k) {
    ASSERT_TRUE(with_failed[k].ok() && without[k].ok()) << toString(methods[k]);
    EXPECT_LT(angleBetween(with_failed[k].v, without[k].v), 1e-9) << toString(methods[k]);
  }
  ASSERT_TRUE(with_failed[2].ok() && all[2].ok());
  EXPECT_LT(angleBetween(with_failed[2].v, all[2].v), 1e-12);
  EXPECT_GT(angleBetweenSignAgnostic(without[2].v, all[2].v), 1e-6);  // the cluster counts for npt
}

}  // namespace
}  // namespace celc::test
