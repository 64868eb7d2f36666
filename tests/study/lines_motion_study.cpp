// The boundary-line table of docs/method.md: the median angle to the truth
// [deg] per method over peer-scene trials on a DAVIS240 and on the peers'
// scene, with the tool's moving line model and the paper's static 5 ms lines
// (tests/lines_motion_scenes.hpp; lines_motion_test.cpp checks the same scenes).
//   build/celc_lines_motion_study
#include <cstdio>

#include "lines_motion_scenes.hpp"

using namespace celc;
using namespace celc::test;

int main() {
  int failed = 0;
  const auto check = [&](const PeerSceneTrial& tr) {
    if (!tr.ok) {
      std::fprintf(stderr, "trial failed: %s\n", tr.message.c_str());
      ++failed;
    }
  };
  const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::Ce3lc, Method::Npt};
  LineFitOptions paper;
  paper.model = LineModel::Static;
  paper.interval_fraction = 0.0;
  std::printf("| scene | lines | celc | celc_opt | ce3lc | npt |\n|---|---|---|---|---|---|\n");
  auto row = [&](const char* name, PeerSceneOptions o, int n) {
    for (int model = 0; model < 2; ++model) {
      o.line_fit = model == 0 ? LineFitOptions{} : paper;
      const Outcome r = runSceneTrials(o, methods, n, 500, check);
      std::printf("| %s | %s |", name, model == 0 ? "moving (default)" : "static 5 ms (paper)");
      for (const auto& d : r.deg) std::printf(" %.3g |", median(d));
      std::printf("\n");
    }
  };
  row("float, 4 m/s, 0.2 s, still", davis240Scene(4.0, 0.2, 0.0), 20);
  row("float, 4 m/s, 0.2 s, 3 rad/s", davis240Scene(4.0, 0.2, 3.0), 20);
  for (double omega : {0.0, 3.0}) {
    PeerSceneOptions o = davis240Scene(3.0, 0.5, omega);
    o.integer_pixels = true;
    o.events_per_line = 2000;
    row(omega == 0.0 ? "integer, 3 m/s, 0.5 s, still" : "integer, 3 m/s, 0.5 s, 3 rad/s", o, 20);
  }
  for (int events : {20, 200}) {
    PeerSceneOptions o;  // the peers' scene: 640 x 480, f 320, 2 m/s, 1 px, 15 deg/s
    o.events_per_line = events;
    row(events == 20 ? "peers, 5 x 20" : "peers, 5 x 200", o, 50);
  }
  return failed == 0 ? 0 : 1;
}
