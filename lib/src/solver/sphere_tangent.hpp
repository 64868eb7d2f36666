#pragma once
// Internal: the tangent plane of the unit sphere, for the solvers that move a
// unit vector (v, a line's plane normal) by a 2-vector step.
#include <cmath>

#include "celc/core/types.hpp"

namespace celc::detail {

using Mat32 = Eigen::Matrix<double, 3, 2>;

/// An orthonormal basis (columns) of the tangent plane of the unit sphere at u.
inline Mat32 tangentBasis(const Vec3& u) {
  const Vec3 a = std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 b1 = u.cross(a).normalized();
  Mat32 B;
  B.col(0) = b1;
  B.col(1) = u.cross(b1);
  return B;
}

}  // namespace celc::detail
