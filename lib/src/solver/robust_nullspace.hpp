#pragma once
// Internal: the robust nullspace of the linear stage. Minimises
// sum rho(a_i^T v / |N_i v|) over unit v by IRLS with Huber weights and a MAD
// scale, from several starts (the generalised eigenvector of
// (sum a a^T, sum N^T N) and, optionally, the best directions of a coarse
// hemisphere grid); the end point with the lowest robust cost wins.
#include <vector>

#include "celc/solver/options.hpp"
#include "constraint_rows.hpp"

namespace celc::detail {

class PackedRows;

/// The symmetric-definite generalised eigenproblem A x = lambda B x in closed
/// form (A symmetric, B symmetric positive definite): B = L L^T (Cholesky),
/// C = L^-1 A L^-T by Eigen's direct 3x3 symmetric solver polished by Jacobi
/// sweeps, x = L^-T y. Eigenvalues ascending; eigenvectors B-orthonormal
/// (x_i^T B x_j = delta_ij), as Eigen's GeneralizedSelfAdjointEigenSolver
/// gives them, but without its iterations. False when B is not positive definite.
bool generalizedEigen3(const Mat3& A, const Mat3& B, Vec3& values, Mat3& vectors);

struct NullspaceSolution {
  Vec3 v = Vec3::Zero();
  /// Square roots of the two smallest generalised eigenvalues of the final
  /// weighted system: the weighted RMS geometric residual along the best and
  /// the second-best direction.
  double sigma_min = 0.0, sigma_second = 0.0;
  double scale = 0.0;  ///< 1.4826 * median |r| at v [normalised units]
  int iterations = 0;
  bool ok = false;
};

/// IRLS settings from options: max_iterations, huber_k, tolerance and the
/// grid (grid_directions, grid_starts, grid_rows). Fewer than 3 rows: not ok.
NullspaceSolution robustNullspace(const PackedRows& rows, const LinearOptions& options);
/// The same on rows not yet packed.
NullspaceSolution robustNullspace(const std::vector<ConstraintRow>& rows,
                                  const LinearOptions& options);

/// The best keep directions of hemisphereDirections(n), ranked by the median
/// squared geometric residual (a^T v)^2 / |N v|^2 (as the MAD ranks; rows
/// with |N v| = 0 count as 1e300) over every step-th row, step = size / rows
/// (at least 1), the smallest first.
std::vector<Vec3> gridStarts(const PackedRows& rows, int n, int keep, int rows_scored);

/// n directions of a Fibonacci lattice on the upper hemisphere (z > 0): v and
/// -v are one solution of a homogeneous system. Computed once per thread and
/// n (celc_ml's screen asks for the same 100 in every window); the reference
/// stays valid for the thread's life.
const std::vector<Vec3>& hemisphereDirections(int n);

}  // namespace celc::detail
