// CE3LC, the paper's line-line-line baseline: three rows per cluster with a
// middle line, their robust nullspace.
#include "ce3lc.hpp"

#include <vector>

#include "linear_method.hpp"
#include "robust_nullspace.hpp"
#include "stopwatch.hpp"
#include "window_checks.hpp"

namespace celc {

namespace detail {

SolverResult solveCe3lc(const WindowObservations& obs, const MotionModel& motion,
                        const LinearOptions& opt, const WindowFrames& frames,
                        bool check_parallax) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, opt, result)) return result;
  std::vector<int> usable;
  for (int c : usableClusters(obs, 2)) {
    const auto& cl = obs.clusters[c];
    if (cl.has_l2 && cl.l2.normal.allFinite() && cl.l2.normal.norm() > 0.0) usable.push_back(c);
  }
  if (windowIsDegenerate(obs, motion, usable, opt, check_parallax, result)) {
    result.time_us = microsecondsSince(start);
    return result;
  }
  // Per cluster: l_ref(t_m) = B_ref v must be parallel to m2 = R(t_m) l2:
  // [m2]_x B_ref v = 0, three rows (rank two), each normalised by |B_ref v|.
  std::vector<ConstraintRow> rows;
  rows.reserve(3 * usable.size());
  for (int c : usable) {
    const auto& cl = obs.clusters[c];
    Mat3 R2, P2;
    motion.pose(cl.l2.t, R2, P2);
    const Mat3 B = transferMatrix(frames[c], P2);
    const Vec3 m2 = (R2 * cl.l2.normal).normalized();
    Mat3 m2x;
    m2x << 0, -m2.z(), m2.y(), m2.z(), 0, -m2.x(), -m2.y(), m2.x(), 0;
    const Mat3 C = m2x * B;
    for (int j = 0; j < 3; ++j) rows.push_back({C.row(j).transpose(), B});
  }
  const NullspaceSolution ns = robustNullspace(rows, opt);
  result = nullspaceResult(ns, obs, motion, opt, static_cast<int>(rows.size()), frames);
  result.time_us = microsecondsSince(start);
  return result;
}

}  // namespace detail

SolverResult solveCe3lc(const WindowObservations& obs, const MotionModel& motion,
                        const LinearOptions& options) {
  return detail::solveCe3lc(obs, motion, options, detail::WindowFrames(obs, motion), true);
}

}  // namespace celc
