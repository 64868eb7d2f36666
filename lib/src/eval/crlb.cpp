#include "celc/eval/crlb.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "celc/solver/celc_residual.hpp"

namespace celc {
namespace {

using Mat32 = Eigen::Matrix<double, 3, 2>;
using Mat4 = Eigen::Matrix4d;
using Mat24 = Eigen::Matrix<double, 2, 4>;

// Orthonormal basis of the tangent plane of the unit sphere at u.
Mat32 tangentBasis(const Vec3& u) {
  const Vec3 a = std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 b1 = u.cross(a).normalized();
  Mat32 B;
  B.col(0) = b1;
  B.col(1) = u.cross(b1);
  return B;
}

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

}  // namespace

CrlbResult velocityDirectionCrlb(const WindowObservations& truth, const MotionModel& motion,
                                 const Vec3& direction, double sigma_px) {
  CrlbResult out;
  if (!direction.allFinite() || !(direction.norm() > 0.0) || !(sigma_px >= 0.0) ||
      !std::isfinite(sigma_px) || !(truth.focal_px > 0.0)) {
    out.message = "invalid direction, sigma or focal length";
    return out;
  }
  const Vec3 v = direction.normalized();
  const Mat32 Bv = tangentBasis(v);
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();  // Schur complement, accumulated per line
  for (const auto& c : truth.clusters) {
    if (!(c.l3.t > c.l1.t) || !c.l1.normal.allFinite() || !c.l3.normal.allFinite()) continue;
    const ClusterFrame fr = makeClusterFrame(c, motion);
    const Vec3 m1 = fr.m1.normalized(), m3 = fr.m3.normalized();
    const Mat32 B1 = tangentBasis(m1), B3 = tangentBasis(m3);
    Eigen::Matrix2d Ivv = Eigen::Matrix2d::Zero();
    Mat24 Ivl = Mat24::Zero();
    Mat4 Ill = Mat4::Zero();
    int n = 0;
    for (size_t k = 0; k < c.size(); ++k) {
      if (!std::isfinite(c.times[k]) || !c.bearings[k].allFinite()) continue;
      Mat3 Rk, Pk;
      motion.pose(c.times[k], Rk, Pk);
      const EventTerm e = makeEventTerm(fr, Rk, Pk, c.bearings[k]);
      Vec3 gv, g1, g3;
      const double d = eventDistance(e, v, m1, m3, truth.focal_px, &gv, &g1, &g3);
      if (!std::isfinite(d) || !gv.allFinite() || !g1.allFinite() || !g3.allFinite()) continue;
      const Eigen::Vector2d jv = Bv.transpose() * gv;
      Eigen::Vector4d jl;
      jl << B1.transpose() * g1, B3.transpose() * g3;
      Ivv += jv * jv.transpose();
      Ivl += jv * jl.transpose();
      Ill += jl * jl.transpose();
      ++n;
    }
    if (n == 0) continue;
    out.events += n;
    ++out.lines;
    S += Ivv - Ivl * pinvSymmetric(Ill) * Ivl.transpose();
  }
  if (out.events == 0) {
    out.message = "no usable events (clusters need l1, l3 with l3.t > l1.t)";
    return out;
  }
  out.ok = true;
  if (sigma_px == 0.0) return out;  // noise-free: zero bound
  S /= sigma_px * sigma_px;
  S = 0.5 * (S + S.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  if (!(es.eigenvalues()(0) > 1e-12 * std::max(es.eigenvalues()(1), 1e-300))) {
    out.rms_rad = std::numeric_limits<double>::infinity();
    out.covariance.setConstant(std::numeric_limits<double>::infinity());
    out.message = "direction not observable (singular Fisher information)";
    return out;
  }
  out.covariance = S.inverse();
  out.rms_rad = std::sqrt(out.covariance.trace());
  return out;
}

}  // namespace celc
