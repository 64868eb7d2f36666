#pragma once
// Internal: the line profile J(v) (ml_screen.hpp) at many directions in one
// call. The algebra of one cluster at one direction (its 3x3 forms, the
// Cholesky elimination of the line direction, the smallest eigenvalue by
// Newton's iteration) runs in lanes of directions that the compiler
// vectorises (`#pragma omp simd`), compiled like the joint passes
// (isa_clones.hpp): the lattice's 100 directions, or a descent's stencil of
// 5, cost a few evaluations' time instead of one each.
#include <cstddef>

namespace celc::detail {

/// Doubles per cluster in the packed sums: S row-major (9), then
/// beta[a][j] (3 x 3 vectors of 3: B(v)_aj = beta[a][j].v), then the 6
/// quadratic forms Hq[p] of H(v) row-major (54), p over the pairs
/// (0,0) (0,1) (0,2) (1,1) (1,2) (2,2).
constexpr size_t kProfileSumsSize = 9 + 27 + 54;

/// out[i] = J at the unit direction (x[i], y[i], z[i]), i < n: the sum over
/// `clusters` packed sums (kProfileSumsSize doubles each) of the smallest
/// eigenvalue of S - B H^-1 B^T, clamped at 0 below; clusters are added in
/// their order, so every n gives the same value at a direction.
void profileValues(const double* sums, size_t clusters, const double* x, const double* y, const double* z,
                   size_t n, double* out);

}  // namespace celc::detail
