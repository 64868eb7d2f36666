#pragma once
// `celc solve`'s path (observeLabelledEvents, as apps/celc/cmd_solve.cpp
// runs it) for a peer-scene trial, shared by the tests and
// tests/study/solve_path_study.cpp: the trial's events as labelled normalised
// pixels, the given configuration's lines and observations sections, the given
// rate as a constant twist from the first event.
#include <utility>
#include <vector>

#include "celc/cluster/to_observations.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/peer_scene.hpp"

namespace celc::test {

/// The observations `celc solve --normalized --omega W` builds from the trial's
/// events; `motion` is set to the constant twist it uses.
inline WindowObservations solvePathObservations(const PeerSceneTrial& tr, const RunConfig& config,
                                                MotionModel& motion) {
  std::vector<Event> events;
  std::vector<int> labels;
  for (size_t c = 0; c < tr.observations.clusters.size(); ++c) {
    const ClusterObservation& cl = tr.observations.clusters[c];
    for (size_t k = 0; k < cl.size(); ++k) {
      Event e;
      e.t = cl.times[k];
      e.x = static_cast<float>(cl.bearings[k].x() / cl.bearings[k].z());
      e.y = static_cast<float>(cl.bearings[k].y() / cl.bearings[k].z());
      events.push_back(e);
      labels.push_back(static_cast<int>(c));
    }
  }
  const double t_ref = tr.given_motion.referenceTime();
  const Vec3 omega = tr.given_motion.meanOmega(t_ref, t_ref + 1.0);
  LabelledObservations in = observeLabelledEvents(
      events, labels, [](const Vec2& p) { return Vec3(p.x(), p.y(), 1.0); }, 320.0, config.observations,
      [&](double t_first) { return MotionModel::constantTwist(omega, t_first); });
  motion = in.motion;
  return std::move(in.observations);
}

}  // namespace celc::test
