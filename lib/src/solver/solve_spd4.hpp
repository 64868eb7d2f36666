#pragma once
// Internal: the 4 x 4 solves of celc_ml's Levenberg-Marquardt (one per
// cluster and try), without the pivoting and the norm that Eigen's LDLT
// computes.
#include <Eigen/Cholesky>

namespace celc::detail {

/// X <- A^-1 X for a symmetric positive definite 4 x 4 A (its lower
/// triangle is read), by A = L D L^T without pivoting; where a pivot is not
/// positive (an indefinite A, or rounding on a near-singular one) by Eigen's
/// pivoted LDL^T instead, which treats a zero pivot as a pseudo-inverse does.
template <int Cols>
inline void solveSpd4(const Eigen::Matrix4d& A, Eigen::Matrix<double, 4, Cols>& X) {
  double L[4][4], D[4], inv[4];
  for (int j = 0; j < 4; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k] * D[k];
    if (!(d > 0.0)) {
      X = A.ldlt().solve(X).eval();
      return;
    }
    D[j] = d;
    inv[j] = 1.0 / d;
    for (int i = j + 1; i < 4; ++i) {
      double a = A(i, j);
      for (int k = 0; k < j; ++k) a -= L[i][k] * L[j][k] * D[k];
      L[i][j] = a * inv[j];
    }
  }
  // L Y = X, then L^T Z = D^-1 Y, the columns side by side.
  for (int i = 1; i < 4; ++i)
    for (int k = 0; k < i; ++k) X.row(i) -= L[i][k] * X.row(k);
  for (int i = 3; i >= 0; --i) {
    X.row(i) *= inv[i];
    for (int k = i + 1; k < 4; ++k) X.row(i) -= L[k][i] * X.row(k);
  }
}

}  // namespace celc::detail
