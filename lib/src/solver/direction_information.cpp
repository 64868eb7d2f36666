// Fisher information about the velocity direction, lines as nuisance.
#include "celc/solver/direction_information.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "celc/solver/celc_residual.hpp"
#include "sampling.hpp"
#include "sphere_tangent.hpp"
#include "thread_buffer.hpp"

namespace celc {
namespace {

using detail::Mat32;
using detail::tangentBasis;
using Mat4 = Eigen::Matrix4d;
using Mat24 = Eigen::Matrix<double, 2, 4>;

// Moore-Penrose pseudo-inverse of a symmetric positive semi-definite matrix.
template <typename M>
M pinvSymmetric(const M& A) {
  const Eigen::SelfAdjointEigenSolver<M> es(A);
  const auto& ev = es.eigenvalues();
  const double tol = 1e-10 * std::max(std::abs(ev(ev.size() - 1)), 1e-300);
  M D = M::Zero();
  for (int i = 0; i < ev.size(); ++i)
    if (ev(i) > tol) D(i, i) = 1.0 / ev(i);
  return es.eigenvectors() * D * es.eigenvectors().transpose();
}

/// DirectionTerms::shift leaves out events beyond this many robust scales.
constexpr double kShiftInlierScales = 3.0;

}  // namespace

DirectionTerms::DirectionTerms(const WindowObservations& obs, const MotionModel& motion, int max_events,
                               const BearingChange* bearing_change)
    : focal_px_(obs.focal_px) {
  detail::borrowSpareVector<DirectionTerms>(terms_);
  std::size_t total = 0;
  for (const auto& c : obs.clusters) total += c.size();
  const std::size_t stride =
      max_events > 0 ? std::max<std::size_t>(1, total / static_cast<std::size_t>(max_events)) : 1;
  reserveWithHeadroom(terms_, total / stride + obs.clusters.size());
  for (const auto& c : obs.clusters) {
    if (!c.has_lines || !(c.l3.t > c.l1.t) || !c.l1.normal.allFinite() || !c.l3.normal.allFinite()) continue;
    if (!(c.l1.normal.norm() > 0.0) || !(c.l3.normal.norm() > 0.0)) continue;
    const ClusterFrame fr = makeClusterFrame(c, motion);
    for (size_t k = 0; k < c.size() && k < c.bearings.size(); k += stride) {
      if (!std::isfinite(c.times[k]) || !c.bearings[k].allFinite()) continue;
      Mat3 Rk, Pk;
      motion.pose(c.times[k], Rk, Pk);
      Vec3 f = c.bearings[k];
      if (bearing_change) f.head<2>() = bearing_change->scale * f.head<2>() + bearing_change->offset;
      terms_.push_back(makeEventTerm(fr, Rk, Pk, f));
    }
    begin_.push_back(terms_.size());
    m1_.push_back(fr.m1.normalized());
    m3_.push_back(fr.m3.normalized());
  }
}

DirectionTerms::~DirectionTerms() {
  // Hand the memory back for the next window.
  detail::returnSpareVector<DirectionTerms>(terms_);
}

DirectionInformation DirectionTerms::information(const Vec3& direction, bool keep_residuals) const {
  DirectionInformation out;
  if (!direction.allFinite() || !(direction.norm() > 0.0) || !(focal_px_ > 0.0)) {
    out.message = "invalid direction or focal length";
    return out;
  }
  const Vec3 v = direction.normalized();
  const Mat32 Bv = tangentBasis(v);
  for (size_t c = 0; c < m1_.size(); ++c) {
    const Vec3& m1 = m1_[c];
    const Vec3& m3 = m3_[c];
    const Mat32 B1 = tangentBasis(m1), B3 = tangentBasis(m3);
    Eigen::Matrix2d Ivv = Eigen::Matrix2d::Zero();
    Mat24 Ivl = Mat24::Zero();
    Mat4 Ill = Mat4::Zero();
    int n = 0;
    for (size_t k = begin_[c]; k < begin_[c + 1]; ++k) {
      Vec3 gv, g1, g3;
      const double d = eventDistance(terms_[k], v, m1, m3, focal_px_, &gv, &g1, &g3);
      if (!std::isfinite(d) || !gv.allFinite() || !g1.allFinite() || !g3.allFinite()) continue;
      const Eigen::Vector2d jv = Bv.transpose() * gv;
      Eigen::Vector4d jl;
      jl << B1.transpose() * g1, B3.transpose() * g3;
      Ivv += jv * jv.transpose();
      Ivl += jv * jl.transpose();
      Ill += jl * jl.transpose();
      if (keep_residuals) out.residuals_px.push_back(d);
      ++n;
    }
    if (n == 0) continue;
    out.events += n;
    ++out.lines;
    out.schur += Ivv - Ivl * pinvSymmetric(Ill) * Ivl.transpose();
  }
  if (out.events == 0) {
    out.message = "no usable events (clusters need l1, l3 with l3.t > l1.t)";
    return out;
  }
  out.ok = true;
  return out;
}

Eigen::Vector2d DirectionTerms::shift(const Vec3& direction, const DirectionTerms& changed) const {
  return shifts(direction, {&changed}).front();
}

namespace {

/// One cluster's information blocks (I_vv, I_vl, I_ll) summed over events.
struct InformationBlocks {
  Eigen::Matrix2d vv = Eigen::Matrix2d::Zero();
  Mat24 vl = Mat24::Zero();
  Mat4 ll = Mat4::Zero();
  void add(const Eigen::Vector2d& jv, const Eigen::Vector4d& jl) {
    vv += jv * jv.transpose();
    vl += jv * jl.transpose();
    ll += jl * jl.transpose();
  }
};

/// -S^-1 b, NaN when S is singular (eigenvalue ratio below 1e-12).
Eigen::Vector2d solveShift(Eigen::Matrix2d S, const Eigen::Vector2d& b) {
  S = 0.5 * (S + S.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  if (!(es.eigenvalues()(0) > 1e-12 * std::max(es.eigenvalues()(1), 1e-300)))
    return Eigen::Vector2d::Constant(NAN);
  return -S.inverse() * b;
}

}  // namespace

std::vector<Eigen::Vector2d> DirectionTerms::shifts(const Vec3& direction,
                                                    const std::vector<const DirectionTerms*>& changed) const {
  const size_t m = changed.size();
  std::vector<Eigen::Vector2d> out(m, Eigen::Vector2d::Constant(NAN));
  if (!direction.allFinite() || !(direction.norm() > 0.0) || !(focal_px_ > 0.0)) return out;
  for (const DirectionTerms* other : changed)
    if (other == nullptr || other->begin_ != begin_) return out;
  const Vec3 v = direction.normalized();
  const Mat32 Bv = tangentBasis(v);
  // Events beyond kShiftInlierScales robust scales of their line at the
  // estimate are left out, as the robust stages leave them: near a line with
  // no image direction a residual's change is not first order.
  std::vector<double> residuals;
  residuals.reserve(terms_.size());
  for (size_t c = 0; c < m1_.size(); ++c)
    for (size_t k = begin_[c]; k < begin_[c + 1]; ++k) {
      const double d = eventDistance(terms_[k], v, m1_[c], m3_[c], focal_px_, nullptr, nullptr, nullptr);
      if (std::isfinite(d)) residuals.push_back(d);
    }
  if (residuals.empty()) return out;
  const double limit = kShiftInlierScales * 1.4826 * detail::medianAbs(residuals);
  // The blocks of the unchanged terms are shared by every change; an event
  // whose changed residual is not finite leaves that change's sums only,
  // through its own `excluded` blocks.
  std::vector<Eigen::Matrix2d> S(m, Eigen::Matrix2d::Zero());
  std::vector<Eigen::Vector2d> b(m, Eigen::Vector2d::Zero());
  std::vector<Eigen::Vector2d> av(m);
  std::vector<Eigen::Vector4d> al(m);
  std::vector<InformationBlocks> excluded(m);
  std::vector<char> has_excluded(m);
  std::vector<double> g(m);
  for (size_t c = 0; c < m1_.size(); ++c) {
    const Vec3& m1 = m1_[c];
    const Vec3& m3 = m3_[c];
    const Mat32 B1 = tangentBasis(m1), B3 = tangentBasis(m3);
    InformationBlocks shared;
    std::fill(av.begin(), av.end(), Eigen::Vector2d::Zero());
    std::fill(al.begin(), al.end(), Eigen::Vector4d::Zero());
    std::fill(excluded.begin(), excluded.end(), InformationBlocks{});
    std::fill(has_excluded.begin(), has_excluded.end(), 0);
    for (size_t k = begin_[c]; k < begin_[c + 1]; ++k) {
      Vec3 gv, g1, g3;
      const double d = eventDistance(terms_[k], v, m1, m3, focal_px_, &gv, &g1, &g3);
      if (!std::isfinite(d) || !gv.allFinite() || !g1.allFinite() || !g3.allFinite()) continue;
      if (limit > 0.0 && std::abs(d) > limit) continue;
      const Eigen::Vector2d jv = Bv.transpose() * gv;
      Eigen::Vector4d jl;
      jl << B1.transpose() * g1, B3.transpose() * g3;
      shared.add(jv, jl);
      for (size_t j = 0; j < m; ++j) {
        const double d_changed = eventDistance(changed[j]->terms_[k], v, m1, m3, focal_px_, nullptr, nullptr, nullptr);
        if (!std::isfinite(d_changed)) {
          excluded[j].add(jv, jl);
          has_excluded[j] = 1;
          continue;
        }
        g[j] = d_changed - d;
        av[j] += jv * g[j];
        al[j] += jl * g[j];
      }
    }
    const Mat4 shared_pinv = pinvSymmetric(shared.ll);
    const Eigen::Matrix2d shared_schur = shared.vv - shared.vl * shared_pinv * shared.vl.transpose();
    for (size_t j = 0; j < m; ++j) {
      if (!has_excluded[j]) {
        S[j] += shared_schur;
        b[j] += av[j] - shared.vl * shared_pinv * al[j];
        continue;
      }
      const Mat24 vl = shared.vl - excluded[j].vl;
      const Mat4 pinv = pinvSymmetric(Mat4(shared.ll - excluded[j].ll));
      S[j] += shared.vv - excluded[j].vv - vl * pinv * vl.transpose();
      b[j] += av[j] - vl * pinv * al[j];
    }
  }
  for (size_t j = 0; j < m; ++j) out[j] = solveShift(S[j], b[j]);
  return out;
}

double DirectionTerms::sigmaDeg(const Vec3& direction, double scale) const {
  DirectionInformation info = information(direction, true);
  if (!info.ok) return NAN;
  const double s = 1.4826 * detail::medianAbs(info.residuals_px);
  if (!(s > 0.0) || !std::isfinite(s)) return NAN;
  const DirectionCovariance c = directionCovariance(info.schur, s);
  if (!c.observable) return std::numeric_limits<double>::infinity();
  return scale * c.rms_rad * 180.0 / M_PI;
}

DirectionInformation directionInformation(const WindowObservations& obs, const MotionModel& motion,
                                          const Vec3& direction, int max_events, bool keep_residuals) {
  if (!direction.allFinite() || !(direction.norm() > 0.0) || !(obs.focal_px > 0.0)) {
    DirectionInformation out;
    out.message = "invalid direction or focal length";
    return out;
  }
  return DirectionTerms(obs, motion, max_events).information(direction, keep_residuals);
}

DirectionCovariance directionCovariance(const Eigen::Matrix2d& schur, double sigma_px) {
  DirectionCovariance out;
  if (sigma_px == 0.0) {
    out.observable = true;  // noise-free: zero covariance
    return out;
  }
  Eigen::Matrix2d S = schur / (sigma_px * sigma_px);
  S = 0.5 * (S + S.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  if (!(es.eigenvalues()(0) > 1e-12 * std::max(es.eigenvalues()(1), 1e-300))) {
    out.rms_rad = std::numeric_limits<double>::infinity();
    out.covariance.setConstant(std::numeric_limits<double>::infinity());
    return out;
  }
  out.observable = true;
  out.covariance = S.inverse();
  out.rms_rad = std::sqrt(out.covariance.trace());
  return out;
}

double directionSigmaDeg(const WindowObservations& obs, const MotionModel& motion,
                         const Vec3& direction, double scale, int max_events) {
  if (!direction.allFinite() || !(direction.norm() > 0.0) || !(obs.focal_px > 0.0)) return NAN;
  return DirectionTerms(obs, motion, max_events).sigmaDeg(direction, scale);
}

}  // namespace celc
