#pragma once
// Correction of the radial bias of the edge points on curved contours.
//
// On a blurred disc of radius r the slope maximum lies about sigma^2 / (2 r) inside the true
// edge, and the facet / profile fit see the curved edge through their windows; what remains
// after detectSubpixelEdges has removed its own window bias (see subpixel_edges.cpp) is about
// `coefficient / r` pixels towards the centre of curvature (calibrated by bench_edges on rendered
// discs, blur 0.8-1.5). The correction estimates the signed curvature from the turn of the normals
// along the linked contour,
//   kappa_n = (p_b - p_a) . (n_b - n_a) / |p_b - p_a|^2   (positive: centre on the -n side),
// over neighbours `halfWindow` points either side, and moves each point away from the centre
// of curvature by coefficient * |kappa_n|.

#include <vector>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct CurvatureBiasParams {
  double coefficient = 0.5;  // pixels^2: blur part of the bias = coefficient / radius
  int halfWindow = 4;        // points either side used for the curvature estimate
};

// The coefficient k of the remaining bias k / r for blur `sigma` (pixels), calibrated with
// bench_edges on rendered discs of radius 10..200 at blur 0.8, 1.0 and 1.5.
double curvatureBiasCoefficient(double sigma);

// Signed curvature kappa_n (1/pixels, convention above) of every point from the turn of the
// normals along its contour; 0 for points on contours shorter than 2 * halfWindow + 1.
std::vector<double> contourCurvatures(const std::vector<EdgePoint>& points,
                                      const std::vector<std::vector<int>>& contours,
                                      int halfWindow = 4);

// Corrects `points` in place along each contour of `contours` (index lists into `points`).
// Contours shorter than 2 * halfWindow + 1 points are left unchanged.
void correctCurvatureBias(std::vector<EdgePoint>& points,
                          const std::vector<std::vector<int>>& contours,
                          const CurvatureBiasParams& params = {});

}  // namespace facet
