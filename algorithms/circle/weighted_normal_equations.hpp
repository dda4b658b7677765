#pragma once
// The normal equations J^T W J and J^T W r of a weighted least-squares step over many rows and a
// few columns (the grey-value circle fit: about 2,000 band pixels, up to 8 parameters), in one
// pass over the rows per pair of columns instead of one pass per entry.
//
// Each entry as a dot product of two columns reads both columns again: 33 passes over the rows
// for 6 parameters, most of their time spent loading. Here a pass takes two rows of the matrix at
// once and every column right of them, so each column is loaded a few times in all and the sums
// stay in registers.

#include <cstddef>
#include <span>

namespace facet {

// `columns`: k <= 8 pointers to columns of J, each of n values; `weight`, `residual`: n values.
// Writes the k x k matrix J^T W J (row-major, both triangles) to `jtj` and J^T W r (k values) to
// `jtr`. The sums are taken in another order than a plain loop's: they agree to rounding.
void weightedNormalEquations(std::span<const double* const> columns, const double* weight,
                             const double* residual, std::ptrdiff_t n, double* jtj, double* jtr);

// Only the first two rows of J^T W J (and their mirror, the first two columns) and the first two
// entries of J^T W r, in one pass: a score test of two parameters at a fit of the others, whose
// block of the matrix the fit has already computed. `columns`: 2 <= k <= 8; the other entries of
// `jtj` and `jtr` are left as they are.
void weightedNormalEquationsLeadingPair(std::span<const double* const> columns,
                                        const double* weight, const double* residual,
                                        std::ptrdiff_t n, double* jtj, double* jtr);

}  // namespace facet
