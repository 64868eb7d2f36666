// celc_ml's rate-offset search: Nelder-Mead on the concentrated joint cost.
#include "rate_offset.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "constraint_rows.hpp"
#include "joint_refine.hpp"

namespace celc::detail {

namespace {

constexpr double kRadPerDeg = M_PI / 180.0;
// The first simplex spans this much of each axis [deg/s] (measured on the
// peer study's rate-error cells, where the offset's spread is 3-4 deg/s).
constexpr double kStepDegS = 3.0;
// The search stops when the simplex spans less than this [deg/s] (0.05 was
// measured to move no median by more than 0.2 deg, at 1.5x the time) ...
constexpr double kToleranceDegS = 0.5;
// ... or after this many values of C.
constexpr int kMaxEvaluations = 150;

struct Vertex {
  Vec3 delta;  // [rad/s]
  double cost = INFINITY;
  Vec3 v = Vec3::Zero();
};

}  // namespace

RateOffsetFit searchRateOffset(const WindowObservations& obs, const MotionModel& motion, const Vec3& v,
                               const SolverOptions& options, std::uint64_t event_seed, double huber_px) {
  RateOffsetFit fit;
  int events = 0;
  Vec3 v_best = v;
  auto value = [&](const Vec3& delta) {
    ++fit.evaluations;
    const MotionModel shifted = motion.withOmegaOffset(delta);
    const WindowFrames frames(obs, shifted);
    const JointProblem problem(obs, shifted, frames, options.ml.max_events, options.refine.balance_clusters,
                               event_seed, huber_px);
    const JointProblem::Result r = problem.refine(problem.start(v_best), options.refine.max_iterations,
                                                  options.refine.function_tolerance);
    Vertex out{delta};
    if (r.ok && std::isfinite(r.cost)) out.cost = r.cost, out.v = r.state.v, events = r.events;
    return out;
  };
  std::array<Vertex, 4> x;
  x[0] = value(Vec3::Zero());
  const double c0 = x[0].cost;
  const int n0 = events;
  fit.v = x[0].v;
  if (!std::isfinite(c0) || n0 == 0 || !(c0 > 0.0)) return fit;
  v_best = x[0].v;
  for (int i = 1; i < 4; ++i) x[static_cast<size_t>(i)] = value(Vec3::Unit(i - 1) * kStepDegS * kRadPerDeg);
  auto byCost = [](const Vertex& a, const Vertex& b) { return a.cost < b.cost; };
  while (fit.evaluations < kMaxEvaluations) {
    std::sort(x.begin(), x.end(), byCost);
    if (std::isfinite(x[0].cost)) v_best = x[0].v;
    double span = 0.0;
    for (const Vertex& p : x) span = std::max(span, (p.delta - x[0].delta).norm());
    if (span < kToleranceDegS * kRadPerDeg) break;
    const Vec3 centroid = (x[0].delta + x[1].delta + x[2].delta) / 3.0;
    const Vertex reflected = value(centroid + (centroid - x[3].delta));
    if (reflected.cost < x[0].cost) {
      const Vertex expanded = value(centroid + 2.0 * (centroid - x[3].delta));
      x[3] = expanded.cost < reflected.cost ? expanded : reflected;
    } else if (reflected.cost < x[2].cost) {
      x[3] = reflected;
    } else {
      const Vertex contracted = value(centroid + 0.5 * (x[3].delta - centroid));
      if (contracted.cost < x[3].cost) {
        x[3] = contracted;
      } else {
        for (size_t i = 1; i < 4; ++i) x[i] = value(x[0].delta + 0.5 * (x[i].delta - x[0].delta));
      }
    }
  }
  const Vertex& best = *std::min_element(x.begin(), x.end(), byCost);
  if (!std::isfinite(best.cost)) return fit;
  fit.delta = best.delta;
  fit.v = best.v;
  const double sigma2 = 2.0 * c0 / n0;
  fit.likelihood_ratio = 2.0 * (c0 - best.cost) / sigma2;
  fit.accepted = fit.likelihood_ratio > kRateOffsetGate;
  return fit;
}

}  // namespace celc::detail
