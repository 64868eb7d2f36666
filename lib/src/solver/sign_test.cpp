// The cheirality sign test.
#include "sign_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

namespace celc {

namespace detail {

namespace {
// One cluster's cheirality votes: every stride-th event votes for the sign of
// its depth lambda. Counted sequentially, so that the count can stop as soon as
// the majority is decided and resume when the exact event balance is needed.
struct SignVotes {
  const ClusterObservation* cl = nullptr;
  ClusterRowTerms terms;
  size_t stride = 1, next = 0;
  long pos = 0, neg = 0;

  SignVotes(const ClusterObservation& c, const ClusterFrame& frame, const MotionModel& motion)
      : cl(&c), terms(frame, motion) {}
  // lambda of the event (t, f) from the cluster's terms; NaN when it sees
  // neither plane.
  // With an acceleration a (celc_acc.hpp): p = P v + q a, q = (t - t_ref)^2 / 2.
  const Vec3* a = nullptr;
  double t_ref = 0.0;
  double depth(double t, const Vec3& f, const Vec3& v) const {
    const EventLineTerms e = terms.at(t);
    const double a1 = e.g1.dot(f), a3 = e.g3.dot(f);
    double d1 = e.s.dot(v), d3 = e.u.dot(v);
    if (a) {
      auto q = [this](double x) { return 0.5 * (x - t_ref) * (x - t_ref); };
      const ClusterFrame& fr = terms.frame();
      d1 += (q(cl->l1.t) - q(t)) * fr.m1.dot(*a);
      d3 += (q(cl->l3.t) - q(t)) * fr.m3.dot(*a);
    }
    const double den = a1 * a1 + a3 * a3;
    if (!(den > 1e-24)) return NAN;
    return (a1 * d1 + a3 * d3) / den;
  }
  size_t remaining() const { return next < cl->size() ? (cl->size() - 1 - next) / stride + 1 : 0; }
  // Counts votes until the majority cannot change (or all are counted).
  void count(const Vec3& v, bool all) {
    for (; next < cl->size(); next += stride) {
      if (!all && static_cast<size_t>(std::abs(pos - neg)) > remaining()) return;
      const double lambda = depth(cl->times[next], cl->bearings[next], v);
      if (std::isnan(lambda)) continue;
      if (lambda > 0) ++pos;
      else if (lambda < 0) ++neg;
    }
  }
};
}  // namespace

SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v,
                         const WindowFrames& frames) {
  return resolveSign(obs, motion, v, nullptr, frames);
}

SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v, const Vec3* a,
                         const WindowFrames& frames) {
  // Depth of event k along its ray from the camera at t_k, where the ray meets
  // the planes of l1 and l3 (least squares over both planes):
  //   lambda = sum_i (m_i.f')(m_i.(p_i - p_k)) / sum_i (m_i.f')^2,  f' = R_k f_k, p = P v,
  // that is (g1.f (s.v) + g3.f (u.v)) / ((g1.f)^2 + (g3.f)^2) in EventLineTerms.
  // lambda is odd in v, so exactly one sign puts the line in front (lambda > 0).
  // Each cluster votes by the majority of kSignVotesPerCluster of its events; a
  // cluster's count stops once its majority is decided, and is completed only
  // when the clusters tie and the event balance decides.
  std::vector<SignVotes> clusters;
  clusters.reserve(frames.clusters().size());
  for (int c : frames.clusters()) {
    SignVotes& s = clusters.emplace_back(obs.clusters[c], frames[c], motion);
    s.a = a;
    s.t_ref = motion.referenceTime();
    s.stride = std::max<size_t>(1, s.cl->size() / kSignVotesPerCluster);
    s.count(v, false);
  }
  // A line that hardly moved (rotation removed) carries almost no depth:
  // each cluster's vote counts by its line's motion, up to kSignFullWeightPx,
  // and, where its own l1 .. l3 span less than kSignFullSpanShare of the
  // window's (first l1 to last l3), in proportion to its span: a line seen
  // over a short time moved mostly by its fits' and the rotation's errors
  // (docs/method.md).
  double t_first = std::numeric_limits<double>::infinity(), t_last = -t_first;
  for (const SignVotes& s : clusters) {
    t_first = std::min(t_first, s.cl->l1.t);
    t_last = std::max(t_last, s.cl->l3.t);
  }
  const double window = t_last - t_first;
  double votes = 0.0, weights = 0.0;
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    const SignVotes& s = clusters[i];
    if (s.pos == s.neg) continue;
    const double moved = frames.lineMotionPx(frames.clusters()[i]);
    const double share =
        window > 0.0 ? std::clamp((s.cl->l3.t - s.cl->l1.t) / (kSignFullSpanShare * window), 0.0, 1.0) : 1.0;
    const double w = std::isfinite(moved) && std::isfinite(share) ? std::min(moved, kSignFullWeightPx) * share : 0.0;
    votes += s.pos > s.neg ? w : -w;
    weights += w;
  }
  SignDecision d;
  if (!(weights > 0.0)) return d;
  d.margin = votes / weights;
  if (votes != 0.0) {
    d.sign = votes > 0.0 ? 1 : -1;
    return d;
  }
  long event_balance = 0;
  for (auto& s : clusters) {
    s.count(v, true);
    if (s.pos != s.neg) event_balance += s.pos - s.neg;
  }
  d.sign = event_balance >= 0 ? 1 : -1;
  return d;
}

}  // namespace detail

SignDecision resolveSign(const WindowObservations& obs, const MotionModel& motion, const Vec3& v) {
  return detail::resolveSign(obs, motion, v, detail::WindowFrames(obs, motion));
}

}  // namespace celc
