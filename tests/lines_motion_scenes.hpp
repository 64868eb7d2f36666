#pragma once
// The scenes of the boundary-line tests under motion (lines_motion_test.cpp)
// and of their table (tests/study/lines_motion_study.cpp): the peer scene on a
// DAVIS240, true clusters, the tool's line fit, the solvers.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "celc/eval/metrics.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/sim/render_sequence.hpp"
#include "celc/solver/solver.hpp"

namespace celc::test {

inline const double kDeg = 180.0 / M_PI;

// A DAVIS240 moving at V through segments 3-6 m away, no pixel noise.
inline PeerSceneOptions davis240Scene(double speed, double duration, double omega_rad_s) {
  PeerSceneOptions o;
  o.camera = cameraPreset("davis240");  // 240 x 180, f = 200 px, no distortion
  o.speed = speed;
  o.duration = duration;
  o.depth_range = Vec2(3.0, 6.0);
  o.omega_deg_s = omega_rad_s * kDeg;
  o.event_noise_px = 0.0;
  o.min_separation_px = 60.0;
  return o;
}

// Per method, the angle to the truth [deg] of every trial (180 when not ok),
// and the lines rejected over all trials.
struct Outcome {
  std::vector<std::vector<double>> deg;
  int lines_rejected = 0, trials = 0;
};

/// `n` trials from `seed` on; `check(trial)` sees every generated trial (a failed one is left out).
template <class CheckTrial>
Outcome runSceneTrials(const PeerSceneOptions& o, const std::vector<Method>& methods, int n, std::uint64_t seed,
                       CheckTrial&& check) {
  Outcome out;
  out.deg.resize(methods.size());
  for (int i = 0; i < n; ++i) {
    std::mt19937_64 rng(seed + static_cast<std::uint64_t>(i));
    const PeerSceneTrial tr = generatePeerScene(o, rng);
    check(tr);
    if (!tr.ok) continue;
    ++out.trials;
    out.lines_rejected += o.n_lines - tr.lines_fitted;
    const auto res = solveMethods(tr.observations, tr.given_motion, methods, SolverOptions::paper());
    for (size_t k = 0; k < methods.size(); ++k)
      out.deg[k].push_back(res[k].ok() ? directionAngle(tr.true_direction, res[k].v) * kDeg : 180.0);
  }
  return out;
}

inline double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace celc::test
