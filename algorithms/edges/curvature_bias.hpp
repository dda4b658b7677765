#pragma once
// Correction of the radial bias of the edge points on curved contours.
//
// Two effects move the points towards the centre of curvature on a contour of radius r:
// - the blur: on a blurred disc the slope maximum lies about sigma^2 / (2 r) inside the true
//   edge; with the profile fit it is `coefficient / r` (calibrated by bench_edges on rendered
//   discs, blur 0.8-1.5);
// - the straight-line profile fit averages the arc over its window along the edge:
//   profileCurvatureBias(kappa) (edge_profile_fit.hpp), about kappa L (L + 1) / 6.
// The correction estimates the signed curvature from the turn of the normals along the linked
// contour,
//   kappa_n = (p_b - p_a) . (n_b - n_a) / |p_b - p_a|^2   (positive: centre on the -n side),
// over neighbours `halfWindow` points either side, and moves each point away from the centre
// of curvature by the sum of both.

#include <vector>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct CurvatureBiasParams {
  double coefficient = 0.5;   // pixels^2: blur part of the bias = coefficient / radius
  bool profileFitted = true;  // add the profile fit's window bias (points from fitEdgeProfile)
  int halfWindow = 4;         // points either side used for the curvature estimate
};

// Corrects `points` in place along each contour of `contours` (index lists into `points`).
// Contours shorter than 2 * halfWindow + 1 points are left unchanged.
void correctCurvatureBias(std::vector<EdgePoint>& points,
                          const std::vector<std::vector<int>>& contours,
                          const CurvatureBiasParams& params = {});

}  // namespace facet
