// CELC linear: the event rows of every usable cluster, their robust nullspace.
#include "celc_linear.hpp"

#include <cmath>
#include <vector>

#include "irls_kernel.hpp"
#include "linear_method.hpp"
#include "robust_nullspace.hpp"
#include "sampling.hpp"
#include "stopwatch.hpp"
#include "window_checks.hpp"

namespace celc {

namespace detail {

SolverResult solveCelcLinear(const WindowObservations& obs, const MotionModel& motion,
                             const LinearOptions& opt, const WindowFrames& frames,
                             bool check_parallax, std::uint64_t row_seed) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, opt, result)) return result;
  const std::vector<int> usable = usableClusters(obs, opt.min_cluster_events);
  if (windowIsDegenerate(obs, motion, usable, opt, check_parallax, result)) {
    result.time_us = microsecondsSince(start);
    return result;
  }
  // Rows: a seeded subset of each usable cluster's events.
  std::vector<size_t> sizes;
  for (int c : usable) sizes.push_back(obs.clusters[c].size());
  const std::vector<size_t> quota =
      rowQuota(sizes, static_cast<size_t>(opt.max_rows), opt.balance_clusters);
  // Packed as they are built (N's third row is zero: two normaliser rows).
  size_t capacity = 0;
  for (size_t q : quota) capacity += q;
  PackedRows rows(capacity, 2);
  // Per cluster: the sampled finite events; their rows are formed across
  // events, under a constant twist within the series' range
  // (appendTwistRows) or per piece of a gyro-integrated model
  // (appendGyroRows), else (and when a row is not finite) one by one.
  std::vector<double> t, fx, fy, fz;
  for (size_t ci = 0; ci < usable.size(); ++ci) {
    const auto& cl = obs.clusters[usable[ci]];
    const ClusterRowTerms terms(frames[usable[ci]], motion);
    const TwistRowConstants* twist = terms.twist();
    t.clear(), fx.clear(), fy.clear(), fz.clear();
    bool in_series_range = twist != nullptr;
    for (size_t k : sampleIndices(cl.size(), quota[ci], row_seed + ci)) {
      if (!cl.bearings[k].allFinite() || !std::isfinite(cl.times[k])) continue;
      t.push_back(cl.times[k]);
      fx.push_back(cl.bearings[k].x()), fy.push_back(cl.bearings[k].y()), fz.push_back(cl.bearings[k].z());
      if (twist) {
        const double tau = cl.times[k] - twist->t_ref;
        in_series_range = in_series_range && twist->w2 * tau * tau < kTwistSeriesLimit;
      }
    }
    const auto appendOneByOne = [&](size_t begin, size_t end) {
      Vec3 a, n0, n1;
      for (size_t k = begin; k < end; ++k) {
        terms.row(t[k], Vec3(fx[k], fy[k], fz[k]), a, n0, n1);
        if (a.allFinite() && n0.allFinite() && n1.allFinite()) rows.append(a, n0, n1);
      }
    };
    if (twist) {
      if (!in_series_range || !rows.appendTwistRows(*twist, t.data(), fx.data(), fy.data(), fz.data(), t.size()))
        appendOneByOne(0, t.size());
      continue;
    }
    // A gyro-integrated model: across each run of events in one piece.
    size_t next_piece = t.empty() ? 0 : motion.pieceIndex(t[0]);  // each event's piece found once
    for (size_t begin = 0, end; begin < t.size(); begin = end) {
      const size_t piece = next_piece;
      for (end = begin + 1; end < t.size() && (next_piece = motion.pieceIndex(t[end])) == piece;) ++end;
      if (!rows.appendGyroRows(terms.gyroPiece(piece), &t[begin], &fx[begin], &fy[begin], &fz[begin],
                               end - begin))
        appendOneByOne(begin, end);
    }
  }
  rows.seal();
  const NullspaceSolution ns = robustNullspace(rows, opt);
  result = nullspaceResult(ns, obs, motion, opt, static_cast<int>(rows.size()), frames);
  result.time_us = microsecondsSince(start);
  return result;
}

}  // namespace detail

SolverResult solveCelcLinear(const WindowObservations& obs, const MotionModel& motion,
                             const LinearOptions& options) {
  return detail::solveCelcLinear(obs, motion, options, detail::WindowFrames(obs, motion), true,
                                 options.seed);
}

}  // namespace celc
