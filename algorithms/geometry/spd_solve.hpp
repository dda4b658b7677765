#pragma once
// Cholesky solve of a small symmetric positive definite system of a size fixed at compile time:
// the fits that solve one per iteration (an edge profile, a caliper's step) spend as much on a
// general solver's set-up as on their sums.

#include <array>
#include <cmath>

namespace facet {

// Solves A x = y. Reads A's lower triangle (a[i][j], j <= i) and overwrites it with the factor;
// y becomes x. False, with both partly overwritten, when a pivot falls to 1e-9 or below (A
// singular or not positive definite).
template <int N>
bool solveSpd(std::array<std::array<double, N>, N>& a, std::array<double, N>& y) {
  for (int j = 0; j < N; ++j) {
    double d = a[j][j];
    for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
    if (!(d > 1e-9)) return false;
    a[j][j] = std::sqrt(d);
    for (int i = j + 1; i < N; ++i) {
      double v = a[i][j];
      for (int k = 0; k < j; ++k) v -= a[i][k] * a[j][k];
      a[i][j] = v / a[j][j];
    }
  }
  for (int i = 0; i < N; ++i) {
    double v = y[i];
    for (int k = 0; k < i; ++k) v -= a[i][k] * y[k];
    y[i] = v / a[i][i];
  }
  for (int i = N - 1; i >= 0; --i) {
    double v = y[i];
    for (int k = i + 1; k < N; ++k) v -= a[k][i] * y[k];
    y[i] = v / a[i][i];
  }
  return true;
}

}  // namespace facet
