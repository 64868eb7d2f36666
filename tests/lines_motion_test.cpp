// Boundary lines under motion (issue 12): labelled events from 3D segments
// through the tool's own line fit (the moving model, defaults) and solvers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>

#include "celc/eval/metrics.hpp"
#include "celc/lines/line_fit.hpp"
#include "celc/sim/peer_scene.hpp"
#include "celc/solver/solver.hpp"

namespace celc::test {
namespace {

const double kDeg = 180.0 / M_PI;

// DAVIS240-like camera: 240 x 180, f = 200 px.
CameraModel davis240() {
  CameraModel c;
  c.width = 240;
  c.height = 180;
  c.fx = c.fy = 200.0;
  c.cx = 120.0;
  c.cy = 90.0;
  return c;
}

struct Errors {
  std::vector<double> celc, celc_opt, ce3lc, celc_ml, npt;
  int lines_rejected = 0, trials = 0;
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

std::vector<double> line_err;
Errors runScenes(PeerSceneOptions o, int n, std::uint64_t seed) {
  Errors out;
  line_err.clear();
  const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::Ce3lc, Method::CelcMl, Method::Npt};
  for (int i = 0; i < n; ++i) {
    std::mt19937_64 rng(seed + static_cast<std::uint64_t>(i));
    const PeerSceneTrial tr = generatePeerScene(o, rng);
    if (!tr.ok) continue;
    ++out.trials;
    out.lines_rejected += o.n_lines - tr.lines_fitted;
    if (std::getenv("CELC_LINE_ERRORS")) {
      // Endpoint distance [px] of the true segment at the line's time to the fitted line.
      double sum = 0.0;
      int cnt = 0;
      for (size_t k = 0; k < tr.observations.clusters.size(); ++k) {
        const auto& c = tr.observations.clusters[k];
        for (const TimedLine* l : {&c.l1, &c.l3}) {
          Mat3 R, P;
          tr.true_motion.pose(l->t, R, P);
          for (const Vec3& X : tr.segments[k]) {
            const Vec3 Xc = R.transpose() * (X - P * (tr.true_direction * o.speed));
            const Vec3 f = Xc / Xc.z();
            const Vec3 n = l->normal;
            sum += std::fabs(n.dot(f)) / n.head<2>().norm() * tr.observations.focal_px;
            ++cnt;
          }
        }
      }
      line_err.push_back(sum / cnt);
    }
    if (std::getenv("CELC_EXPLORE"))
      for (const auto& c : tr.observations.clusters) {
        const ClusterLines cl = fitClusterLines(c.times, c.bearings, tr.observations.focal_px, o.line_fit, &tr.given_motion);
        if (!cl.ok())
          std::cout << "  rejected: n " << c.size() << " l1 " << toString(cl.l1.status) << " n=" << cl.l1.n_events
                    << " rms " << cl.l1.rms_px << " len " << cl.l1.length_px << " | l3 " << toString(cl.l3.status)
                    << " n=" << cl.l3.n_events << " rms " << cl.l3.rms_px << " len " << cl.l3.length_px << "\n";
      }
    const auto res = solveMethods(tr.observations, tr.given_motion, methods, SolverOptions{});
    if (std::getenv("CELC_EXPLORE"))
      for (int k = 0; k < 5; ++k)
        if (!res[k].ok()) std::cout << "  " << toString(methods[k]) << " " << toString(res[k].status) << " " << res[k].message << "\n";
    auto err = [&](int k) {
      return res[k].ok() ? directionAngle(tr.true_direction, res[k].v) * kDeg : 180.0;
    };
    out.celc.push_back(err(0));
    out.celc_opt.push_back(err(1));
    out.ce3lc.push_back(err(2));
    out.celc_ml.push_back(err(3));
    out.npt.push_back(err(4));
  }
  return out;
}

void print(const char* name, const Errors& e) {
  std::cout << name << ": trials " << e.trials << " rejected lines " << e.lines_rejected
            << " | median deg celc " << median(e.celc) << " celc_opt " << median(e.celc_opt) << " ce3lc "
            << median(e.ce3lc) << " celc_ml " << median(e.celc_ml) << " npt " << median(e.npt)
            << " | max celc " << *std::max_element(e.celc.begin(), e.celc.end()) << " celc_opt "
            << *std::max_element(e.celc_opt.begin(), e.celc_opt.end()) << " ce3lc "
            << *std::max_element(e.ce3lc.begin(), e.ce3lc.end()) << " | line endpoint err px median "
            << median(line_err) << "\n";
}

PeerSceneOptions forwardScene(double omega_deg_s) {
  PeerSceneOptions o;
  o.camera = davis240();
  o.speed = 4.0;
  o.duration = 0.2;
  o.depth_range = Vec2(3.0, 6.0);
  o.omega_deg_s = omega_deg_s;
  o.event_noise_px = 0.0;
  o.min_separation_px = 60.0;
  return o;
}

TEST(LinesMotion, Explore) {
  for (double w : {0.0, 3.0 * kDeg}) {
    PeerSceneOptions o = forwardScene(w);
    print(w == 0 ? "float, still" : "float, 3 rad/s", runScenes(o, 10, 100));
    o.integer_pixels = true;
    o.events_per_line = 2000;
    print(w == 0 ? "integer, still" : "integer, 3 rad/s", runScenes(o, 20, 200));
    for (double fr : {0.05, 0.1, 0.3}) {
      o.line_fit.interval_fraction = fr;
      std::string name = "integer moving fraction " + std::to_string(fr);
      print(name.c_str(), runScenes(o, 20, 200));
    }
    o.line_fit.model = LineModel::Static;
    o.line_fit.interval_fraction = 0.0;
    print(w == 0 ? "integer, still, static 5ms" : "integer, 3 rad/s, static 5ms", runScenes(o, 20, 200));
  }
  for (int epl : {20, 200}) {
    PeerSceneOptions o;
    o.events_per_line = epl;
    print(epl == 20 ? "sparse 5x20" : "5x200", runScenes(o, 20, 300));
  }
}

}  // namespace
}  // namespace celc::test
