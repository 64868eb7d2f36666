// What a result reports: status and degeneracy names, angles between directions.
#include "celc/solver/result.hpp"

#include <algorithm>
#include <cmath>

namespace celc {

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
    case Degeneracy::AccelerationUnobservable: return "acceleration_unobservable";
  }
  return "none";
}

double angleBetween(const Vec3& a, const Vec3& b) {
  // atan2 form: accurate for small and large angles alike.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double angleBetweenSignAgnostic(const Vec3& a, const Vec3& b) {
  const double phi = angleBetween(a, b);
  return std::min(phi, M_PI - phi);
}

}  // namespace celc
