// CELC linear, CE3LC, the sign test and the method dispatcher.
#include "celc/solver/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include "celc/solver/npt.hpp"
#include "constraint_rows.hpp"
#include "irls_kernel.hpp"

namespace celc {

using detail::ClusterFrame;
using detail::ConstraintRow;

std::string toString(Method method) {
  switch (method) {
    case Method::Celc: return "celc";
    case Method::CelcOpt: return "celc_opt";
    case Method::CelcMl: return "celc_ml";
    case Method::Ce3lc: return "ce3lc";
    case Method::Npt: return "npt";
  }
  return "unknown";
}

const std::vector<Method>& allMethods() {
  static const std::vector<Method> all{Method::Celc, Method::CelcOpt, Method::CelcMl,
                                       Method::Ce3lc, Method::Npt};
  return all;
}

Method parseMethod(const std::string& name) {
  for (Method m : allMethods())
    if (toString(m) == name) return m;
  throw std::invalid_argument("unknown method '" + name +
                              "' (expected celc, celc_opt, celc_ml, ce3lc or npt)");
}

std::vector<Method> parseMethodList(const std::string& list) {
  std::vector<Method> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) continue;
    if (item == "all") return allMethods();
    const Method m = parseMethod(item);
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  }
  if (out.empty()) throw std::invalid_argument("empty method list");
  return out;
}

std::string toString(SolveStatus status) {
  switch (status) {
    case SolveStatus::Ok: return "ok";
    case SolveStatus::Degenerate: return "degenerate";
    case SolveStatus::InvalidInput: return "invalid_input";
    case SolveStatus::Failed: return "failed";
  }
  return "failed";
}

std::string toString(Degeneracy reason) {
  switch (reason) {
    case Degeneracy::None: return "none";
    case Degeneracy::TooFewClusters: return "too_few_clusters";
    case Degeneracy::NoParallax: return "no_parallax";
    case Degeneracy::NullspaceNotUnique: return "nullspace_not_unique";
  }
  return "none";
}

std::string LinearOptions::validate() const {
  std::ostringstream e;
  if (max_rows < 0) e << "max_rows must be >= 0; ";
  if (max_iterations < 1) e << "max_iterations must be >= 1; ";
  if (!(huber_k > 0.0)) e << "huber_k must be > 0; ";
  if (!(tolerance > 0.0)) e << "tolerance must be > 0; ";
  if (grid_directions < 0 || grid_starts < 0 || grid_rows < 1)
    e << "grid_directions, grid_starts must be >= 0 and grid_rows >= 1; ";
  if (min_clusters < 1) e << "min_clusters must be >= 1; ";
  if (min_cluster_events < 2) e << "min_cluster_events must be >= 2; ";
  if (!(max_sigma_ratio > 0.0 && max_sigma_ratio <= 1.0)) e << "max_sigma_ratio must be in (0, 1]; ";
  if (!(min_parallax_ratio >= 1.0)) e << "min_parallax_ratio must be >= 1; ";
  if (!(min_parallax_px >= 0.0)) e << "min_parallax_px must be >= 0; ";
  return e.str();
}

std::string RefineOptions::validate() const {
  std::ostringstream e;
  if (!(huber_px > 0.0)) e << "huber_px must be > 0; ";
  if (max_iterations < 1) e << "max_iterations must be >= 1; ";
  if (max_events < 0) e << "max_events must be >= 0; ";
  if (!(function_tolerance > 0.0)) e << "function_tolerance must be > 0; ";
  if (num_threads < 1) e << "num_threads must be >= 1; ";
  return e.str();
}

std::string MlOptions::validate() const {
  std::string e;
  if (!(second_start_deg >= 0.0)) e += "second_start_deg must be >= 0; ";
  if (!(second_start_max_twist >= 0.0)) e += "second_start_max_twist must be >= 0; ";
  if (grid_starts < 0 || grid_starts > 10000) e += "grid_starts must be in [0, 10000]; ";
  if (screen_events < 0) e += "screen_events must be >= 0; ";
  return e;
}

std::string SolverOptions::validate() const {
  return linear.validate() + refine.validate() + npt.validate() + ml.validate();
}

double angleBetween(const Vec3& a, const Vec3& b) {
  // atan2 form: accurate for small and large angles alike.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double angleBetweenSignAgnostic(const Vec3& a, const Vec3& b) {
  const double phi = angleBetween(a, b);
  return std::min(phi, M_PI - phi);
}

namespace {

using Clock = std::chrono::steady_clock;
double microsecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

SolverResult fail(SolveStatus status, Degeneracy reason, std::string message) {
  SolverResult r;
  r.status = status;
  r.degeneracy = reason;
  r.message = std::move(message);
  return r;
}

// Checks shared by the linear solvers; returns true (and fills `result`) when
// the window cannot give a velocity.
bool checkDegenerate(const WindowObservations& obs, const MotionModel& motion,
                     const std::vector<int>& usable, const LinearOptions& opt,
                     SolverResult& result) {
  if (static_cast<int>(usable.size()) < opt.min_clusters) {
    result = fail(SolveStatus::Degenerate, Degeneracy::TooFewClusters,
                  std::to_string(usable.size()) + " usable clusters, need " +
                      std::to_string(opt.min_clusters));
    return true;
  }
  if (!opt.check_parallax) return false;
  int with_events = 0, with_parallax = 0;
  for (int c : usable) {
    if (obs.clusters[c].size() < 8) continue;
    ++with_events;
    const auto p = detail::clusterParallax(obs.clusters[c], motion, obs.focal_px, 120);
    if (p.static_px >= opt.min_parallax_px &&
        p.static_px >= opt.min_parallax_ratio * std::max(p.moving_px, 1e-12))
      ++with_parallax;
  }
  if (with_events > 0 && with_parallax < opt.min_clusters) {
    result = fail(SolveStatus::Degenerate, Degeneracy::NoParallax,
                  std::to_string(with_parallax) + " clusters show parallax, need " +
                      std::to_string(opt.min_clusters));
    return true;
  }
  return false;
}

// Cluster frames a solver has already computed, by cluster index, for the
// sign test to reuse (an empty cache: compute every frame).
struct FrameCache {
  std::vector<ClusterFrame> frames;
  std::vector<char> have;
  explicit FrameCache(size_t clusters = 0) : frames(clusters), have(clusters, 0) {}
  void put(size_t c, const ClusterFrame& f) {
    frames[c] = f;
    have[c] = 1;
  }
  const ClusterFrame* get(size_t c) const { return c < have.size() && have[c] ? &frames[c] : nullptr; }
};
SignDecision resolveSignCached(const WindowObservations& obs, const MotionModel& motion,
                               const Vec3& v, const FrameCache& cache);

// Fills the result from a nullspace solution: degeneracy by singular values, sign.
SolverResult finish(const detail::NullspaceSolution& ns, const WindowObservations& obs,
                    const MotionModel& motion, const LinearOptions& opt, int rows,
                    const FrameCache& cache = FrameCache()) {
  if (!ns.ok) return fail(SolveStatus::Failed, Degeneracy::None, "robust nullspace did not converge");
  SolverResult r;
  r.sigma_min = ns.sigma_min;
  r.sigma_second = ns.sigma_second;
  r.iterations = ns.iterations;
  r.rows_used = rows;
  r.residual_px = ns.scale * obs.focal_px;
  if (ns.sigma_second <= 0.0 || ns.sigma_min > opt.max_sigma_ratio * ns.sigma_second) {
    r.status = SolveStatus::Degenerate;
    r.degeneracy = Degeneracy::NullspaceNotUnique;
    r.message = "two smallest singular values too close (ratio " +
                std::to_string(ns.sigma_second > 0 ? ns.sigma_min / ns.sigma_second : 1.0) + ")";
    return r;
  }
  r.v = ns.v.normalized();
  if (opt.resolve_sign) {
    const SignDecision s = resolveSignCached(obs, motion, r.v, cache);
    r.v *= s.sign;
    r.sign_margin = s.margin * s.sign;
  }
  r.status = SolveStatus::Ok;
  return r;
}

detail::NullspaceOptions nullspaceOptions(const LinearOptions& o) {
  detail::NullspaceOptions n;
  n.max_iterations = o.max_iterations;
  n.huber_k = o.huber_k;
  n.tolerance = o.tolerance;
  n.grid_directions = o.grid_directions;
  n.grid_starts = o.grid_starts;
  n.grid_rows = o.grid_rows;
  return n;
}

// npt's motion model (P(t) = tau I) holds: GyroIntegrated exactly; a constant
// twist while |w| max|tau| / 2 <= max_twist.
bool nptModelHolds(const WindowObservations& obs, const MotionModel& motion, double max_twist) {
  if (motion.kind() == MotionModelKind::GyroIntegrated) return true;
  double tau = 0.0;
  for (const auto& c : obs.clusters)
    for (double t : c.times)
      if (std::isfinite(t)) tau = std::max(tau, std::abs(t - motion.referenceTime()));
  const Vec3 w = motion.meanOmega(motion.referenceTime(), motion.referenceTime() + 1.0);
  return w.norm() * tau / 2.0 <= max_twist;
}

bool validInput(const WindowObservations& obs, const MotionModel& motion, SolverResult& r) {
  if (!(obs.focal_px > 0.0) || !std::isfinite(obs.focal_px)) {
    r = fail(SolveStatus::InvalidInput, Degeneracy::None, "focal length must be positive");
    return false;
  }
  if (!motion.rotation(motion.referenceTime()).allFinite()) {
    r = fail(SolveStatus::InvalidInput, Degeneracy::None, "angular velocity is not finite");
    return false;
  }
  return true;
}

// Options and inputs shared by every linear entry point; true (and `r` set)
// when they cannot be used.
bool rejectInput(const WindowObservations& obs, const MotionModel& motion,
                 const LinearOptions& opt, SolverResult& r) {
  if (const std::string err = opt.validate(); !err.empty()) {
    r = fail(SolveStatus::InvalidInput, Degeneracy::None, "options: " + err);
    return true;
  }
  return !validInput(obs, motion, r);
}

}  // namespace

SolverResult solveCelcLinear(const WindowObservations& obs, const MotionModel& motion,
                             const LinearOptions& opt) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, opt, result)) return result;
  const std::vector<int> usable = detail::usableClusters(obs, opt.min_cluster_events);
  if (checkDegenerate(obs, motion, usable, opt, result)) {
    result.time_us = microsecondsSince(start);
    return result;
  }
  // Rows: a seeded subset of each usable cluster's events.
  std::vector<size_t> sizes;
  for (int c : usable) sizes.push_back(obs.clusters[c].size());
  const std::vector<size_t> quota = detail::rowQuota(sizes, static_cast<size_t>(opt.max_rows), opt.balance_clusters);
  // Packed as they are built (N's third row is zero: two normaliser rows).
  size_t capacity = 0;
  for (size_t q : quota) capacity += q;
  detail::PackedRows rows(capacity, 2);
  for (size_t ci = 0; ci < usable.size(); ++ci) {
    const auto& cl = obs.clusters[usable[ci]];
    const ClusterFrame frame = detail::makeClusterFrame(cl, motion);
    for (size_t k : detail::sampleIndices(cl.size(), quota[ci], opt.seed + ci)) {
      if (!cl.bearings[k].allFinite() || !std::isfinite(cl.times[k])) continue;
      const ConstraintRow row = detail::celcRow(frame, motion, cl.times[k], cl.bearings[k]);
      if (row.a.allFinite() && row.N.allFinite()) rows.append(row.a, row.N);
    }
  }
  rows.seal();
  const auto ns = detail::robustNullspace(rows, nullspaceOptions(opt));
  result = finish(ns, obs, motion, opt, static_cast<int>(rows.size()));
  result.time_us = microsecondsSince(start);
  return result;
}

SolverResult solveCe3lc(const WindowObservations& obs, const MotionModel& motion,
                        const LinearOptions& opt) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, opt, result)) return result;
  std::vector<int> usable;
  for (int c : detail::usableClusters(obs, 0 + 2)) {
    const auto& cl = obs.clusters[c];
    if (cl.has_l2 && cl.l2.normal.allFinite() && cl.l2.normal.norm() > 0.0) usable.push_back(c);
  }
  if (checkDegenerate(obs, motion, usable, opt, result)) {
    result.time_us = microsecondsSince(start);
    return result;
  }
  // Per cluster: l_ref(t_m) = B_ref v must be parallel to m2 = R(t_m) l2:
  // [m2]_x B_ref v = 0, three rows (rank two), each normalised by |B_ref v|.
  std::vector<ConstraintRow> rows;
  rows.reserve(3 * usable.size());
  FrameCache cache(obs.clusters.size());
  for (int c : usable) {
    const auto& cl = obs.clusters[c];
    const ClusterFrame frame = detail::makeClusterFrame(cl, motion);
    cache.put(static_cast<size_t>(c), frame);
    Mat3 R2, P2;
    motion.pose(cl.l2.t, R2, P2);
    const Mat3 B = detail::transferMatrix(frame, P2);
    const Vec3 m2 = (R2 * cl.l2.normal).normalized();
    Mat3 m2x;
    m2x << 0, -m2.z(), m2.y(), m2.z(), 0, -m2.x(), -m2.y(), m2.x(), 0;
    const Mat3 C = m2x * B;
    for (int j = 0; j < 3; ++j) rows.push_back({C.row(j).transpose(), B});
  }
  const auto ns = detail::robustNullspace(rows, nullspaceOptions(opt));
  result = finish(ns, obs, motion, opt, static_cast<int>(rows.size()), cache);
  result.time_us = microsecondsSince(start);
  return result;
}

namespace {
// One cluster's cheirality votes: every stride-th event votes for the sign of
// its depth lambda. Counted sequentially, so that the count can stop as soon as
// the majority is decided and resume when the exact event balance is needed.
struct SignVotes {
  const ClusterObservation* cl = nullptr;
  ClusterFrame fr;
  Vec3 ps, pe;     // P(t_s) v, P(t_e) v
  size_t stride = 1, next = 0;
  long pos = 0, neg = 0;

  size_t remaining() const { return next < cl->size() ? (cl->size() - 1 - next) / stride + 1 : 0; }
  // Counts votes until the majority cannot change (or all are counted).
  void count(const MotionModel& motion, const Vec3& v, bool all) {
    for (; next < cl->size(); next += stride) {
      if (!all && static_cast<size_t>(std::abs(pos - neg)) > remaining()) return;
      Mat3 Rk, Pk;
      motion.pose(cl->times[next], Rk, Pk);
      const Vec3 fp = Rk * cl->bearings[next];
      const Vec3 pk = Pk * v;
      const double a1 = fr.m1.dot(fp), a3 = fr.m3.dot(fp);
      const double den = a1 * a1 + a3 * a3;
      if (!(den > 1e-24)) continue;
      const double lambda = (a1 * fr.m1.dot(ps - pk) + a3 * fr.m3.dot(pe - pk)) / den;
      if (lambda > 0) ++pos;
      else if (lambda < 0) ++neg;
    }
  }
};
SignDecision resolveSignCached(const WindowObservations& obs, const MotionModel& motion,
                               const Vec3& v, const FrameCache& cache) {
  // Depth of event k along its ray from the camera at t_k, where the ray meets
  // the planes of l1 and l3 (least squares over both planes):
  //   lambda = sum_i (m_i.f')(m_i.(p_i - p_k)) / sum_i (m_i.f')^2,  f' = R_k f_k, p = P v.
  // lambda is odd in v, so exactly one sign puts the line in front (lambda > 0).
  // Each cluster votes by the majority of kSignVotesPerCluster of its events; a
  // cluster's count stops once its majority is decided, and is
  // completed only when the clusters tie and the event balance decides.
  std::vector<SignVotes> clusters;
  for (int c : detail::usableClusters(obs, 2)) {
    SignVotes s;
    s.cl = &obs.clusters[c];
    const ClusterFrame* cached = cache.get(static_cast<size_t>(c));
    s.fr = cached ? *cached : detail::makeClusterFrame(*s.cl, motion);
    s.ps = s.fr.Ps * v;
    s.pe = s.fr.Pe * v;
    s.stride = std::max<size_t>(1, s.cl->size() / detail::kSignVotesPerCluster);
    s.count(motion, v, false);
    clusters.push_back(s);
  }
  int votes = 0, voters = 0;
  for (const auto& s : clusters) {
    if (s.pos == s.neg) continue;
    ++voters;
    votes += s.pos > s.neg ? 1 : -1;
  }
  SignDecision d;
  if (voters == 0) return d;
  d.margin = static_cast<double>(votes) / voters;
  if (votes != 0) {
    d.sign = votes > 0 ? 1 : -1;
    return d;
  }
  long event_balance = 0;
  for (auto& s : clusters) {
    s.count(motion, v, true);
    if (s.pos != s.neg) event_balance += s.pos - s.neg;
  }
  d.sign = event_balance >= 0 ? 1 : -1;
  return d;
}
}  // namespace

SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v) {
  return resolveSignCached(obs, motion, v, FrameCache());
}

SolverResult checkWindow(const WindowObservations& obs, const MotionModel& motion,
                         const LinearOptions& opt) {
  const auto start = Clock::now();
  SolverResult result;
  if (rejectInput(obs, motion, opt, result)) return result;
  if (!checkDegenerate(obs, motion, detail::usableClusters(obs, opt.min_cluster_events), opt,
                       result))
    result.status = SolveStatus::Ok;
  result.time_us = microsecondsSince(start);
  return result;
}

namespace {
// celc_ml: the joint refinement from several starts, keeping the end point of
// lowest robust cost (the joint problem has several minima, docs/peers.md).
// Starts: the CELC linear estimate; npt's (when given); ml.grid_starts
// directions of a hemisphere lattice. A start within ml.second_start_deg of
// an end point already found is skipped (same basin). The winner keeps its
// start's singular values and sign margin; a lattice start's sign is resolved
// by cheirality.
SolverResult solveCelcMlMultiStart(const WindowObservations& obs, const MotionModel& motion,
                                   const SolverResult& linear, const SolverResult* npt,
                                   const SolverOptions& options) {
  struct Start {
    Vec3 v;
    const SolverResult* from;  // null: a lattice direction
  };
  std::vector<Start> starts;
  if (linear.ok()) starts.push_back({linear.v, &linear});
  if (npt && npt->ok()) starts.push_back({npt->v, npt});
  if (starts.empty()) return linear;  // neither start: the linear stage's status
  for (const Vec3& d : detail::hemisphereDirections(options.ml.grid_starts)) starts.push_back({d, nullptr});
  double time_us = linear.time_us + (npt ? npt->time_us : 0.0);
  // With a lattice, the starts are screened on a subset of ml.screen_events
  // events (the basins are coarse; every start sees the same subset, so the
  // costs compare) and only the winner is refined on all of them.
  // No screening when the subset would hold every event anyway (refining the
  // winner again would repeat its work).
  size_t events = 0;
  for (const auto& c : obs.clusters) events += c.size();
  const int full = options.refine.max_events;
  const bool screen = options.ml.grid_starts > 0 && options.ml.screen_events > 0 &&
                      (full == 0 || full > options.ml.screen_events) &&
                      events > static_cast<size_t>(options.ml.screen_events);
  RefineOptions screen_options = options.refine;
  if (screen) screen_options.max_events = options.ml.screen_events;
  SolverResult best;
  const SolverResult* best_from = nullptr;
  bool have = false;
  std::vector<Vec3> ends;
  for (const Start& s : starts) {
    bool seen = false;
    for (const Vec3& e : ends)
      seen = seen || angleBetweenSignAgnostic(s.v, e) * 180.0 / M_PI < options.ml.second_start_deg;
    if (seen) continue;
    SolverResult r = refineVelocity(obs, motion, s.v, true, screen_options);
    time_us += r.time_us;
    if (!r.ok()) continue;
    ends.push_back(r.v);
    if (!have || r.residual_px < best.residual_px) {
      best = r;
      best_from = s.from;
      have = true;
    }
  }
  if (!have) return linear.ok() ? linear : *npt;
  if (screen) {
    SolverResult r = refineVelocity(obs, motion, best.v, true, options.refine);
    time_us += r.time_us;
    if (r.ok()) best = r;
  }
  if (best_from) {
    best.sigma_min = best_from->sigma_min;
    best.sigma_second = best_from->sigma_second;
    best.sign_margin = best_from->sign_margin;
  } else {
    best.sigma_min = linear.sigma_min;
    best.sigma_second = linear.sigma_second;
    if (options.linear.resolve_sign) {
      const SignDecision sd = resolveSign(obs, motion, best.v);
      best.v *= sd.sign;
      best.sign_margin = sd.margin * sd.sign;
    }
  }
  best.time_us = time_us;
  return best;
}
}  // namespace

std::vector<SolverResult> solveMethods(const WindowObservations& obs, const MotionModel& motion,
                                       const std::vector<Method>& methods,
                                       const SolverOptions& options_in) {
  std::vector<SolverResult> out;
  // Window-level checks once; a degenerate window is degenerate for every method.
  const SolverResult window = checkWindow(obs, motion, options_in.linear);
  if (!window.ok()) return std::vector<SolverResult>(methods.size(), window);
  SolverOptions options = options_in;
  options.linear.check_parallax = false;
  SolverResult linear;
  bool have_linear = false;
  auto getLinear = [&]() -> const SolverResult& {
    if (!have_linear) {
      linear = solveCelcLinear(obs, motion, options.linear);
      have_linear = true;
    }
    return linear;
  };
  SolverResult npt;
  bool have_npt = false;
  auto getNpt = [&]() -> const SolverResult& {
    if (!have_npt) {
      npt = solveNpt(obs, motion, options.npt);
      if (npt.ok() && options.linear.resolve_sign) {
        const auto t0 = Clock::now();
        const SignDecision s = resolveSign(obs, motion, npt.v);
        npt.v *= s.sign;
        npt.sign_margin = s.margin * s.sign;
        npt.time_us += microsecondsSince(t0);
      }
      have_npt = true;
    }
    return npt;
  };
  for (Method m : methods) {
    switch (m) {
      case Method::Celc: out.push_back(getLinear()); break;
      case Method::Ce3lc: out.push_back(solveCe3lc(obs, motion, options.linear)); break;
      case Method::Npt: out.push_back(getNpt()); break;
      case Method::CelcMl: {
        const bool npt_start =
            options.ml.second_start && nptModelHolds(obs, motion, options.ml.second_start_max_twist);
        out.push_back(solveCelcMlMultiStart(obs, motion, getLinear(),
                                            npt_start ? &getNpt() : nullptr, options));
        break;
      }
      case Method::CelcOpt: {
        const SolverResult& init = getLinear();
        if (!init.ok()) {
          out.push_back(init);
          break;
        }
        SolverResult r = refineVelocity(obs, motion, init.v, false, options.refine);
        r.time_us += init.time_us;  // a refined estimate costs its initialisation too
        r.sigma_min = init.sigma_min;
        r.sigma_second = init.sigma_second;
        r.sign_margin = init.sign_margin;
        out.push_back(r);
        break;
      }
    }
  }
  return out;
}

}  // namespace celc
