#pragma once
// Correction of the radial bias of second-derivative edges on curved contours.
//
// On a blurred curved edge the slope maximum along the gradient moves towards the centre of
// curvature: for a Gaussian-blurred disc of radius r the shift is about sigma^2 / (2 r), and the
// facet window adds its own smoothing. Measured on rendered discs (bench_edges prints the table)
// the points lie about `coefficient / r` pixels inside the true contour. The correction estimates
// the signed curvature from the turn of the normals along the linked contour,
//   kappa_n = (p_b - p_a) . (n_b - n_a) / |p_b - p_a|^2   (positive: centre on the -n side),
// over neighbours `halfWindow` points either side, and moves each point by coefficient * kappa_n
// along its normal, i.e. away from the centre of curvature.

#include <vector>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct CurvatureBiasParams {
  double coefficient = 1.3;  // pixels^2: bias = coefficient / radius
  int halfWindow = 4;        // points either side used for the curvature estimate
};

// Corrects `points` in place along each contour of `contours` (index lists into `points`).
// Contours shorter than 2 * halfWindow + 1 points are left unchanged.
void correctCurvatureBias(std::vector<EdgePoint>& points,
                          const std::vector<std::vector<int>>& contours,
                          const CurvatureBiasParams& params = {});

}  // namespace facet
