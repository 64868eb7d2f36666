#include "celc/eval/metrics.hpp"

#include <algorithm>
#include <cmath>

#include "celc/solver/solver.hpp"

namespace celc {

double directionDistance(const Vec3& truth, const Vec3& estimate) { return (truth - estimate).norm(); }

// The solver's angle (it compares directions too): one formula for both.
double directionAngle(const Vec3& truth, const Vec3& estimate) { return angleBetween(truth, estimate); }

double signAgnosticAngle(double phi) { return std::min(phi, M_PI - phi); }

DirectionErrors directionErrors(const Vec3& truth, const Vec3& estimate) {
  DirectionErrors e;
  e.eps = directionDistance(truth, estimate);
  e.phi = directionAngle(truth, estimate);
  e.phi_sign_agnostic = signAgnosticAngle(e.phi);
  return e;
}

}  // namespace celc
