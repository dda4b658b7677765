#pragma once
// Haralick's cubic facet model on a 5x5 neighbourhood.
//
// The grey values around a pixel are fitted in the least-squares sense by the bicubic
//   f(x, y) = k0 + k1 x + k2 y + k3 x^2 + k4 xy + k5 y^2 + k6 x^3 + k7 x^2 y + k8 x y^2 + k9 y^3
// (x right, y down, origin at the pixel centre). Because the discrete orthogonal polynomials
// 1, r, r^2 - 2, r^3 - 17/5 r on r = -2..2 make the fit a set of fixed separable projections, the
// ten coefficients are ten fixed 5x5 convolution kernels (Haralick 1984, "Digital step edges
// from zero crossing of second directional derivatives").
//
// Along the unit gradient direction n = (k1, k2)/|(k1, k2)| the fit reads
//   f(rho n) = C0 + C1 rho + C2 rho^2 + C3 rho^3,
// and the edge lies at the zero crossing of the second directional derivative, rho = -C2/(3 C3),
// which is a maximum of the first derivative only when C3 < 0.

#include <array>
#include <optional>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

using FacetCoefficients = std::array<double, 10>;  // k0..k9 as above, grey levels on 8-bit scale

// Fit at pixel `p` of a CV_8UC1 or CV_16UC1 image (16-bit values are divided by 256). `p` must be
// at least 2 pixels inside the image.
FacetCoefficients fitCubicFacet(const cv::Mat& image, cv::Point p);

struct FacetZeroCrossing {
  double rho = 0;                 // offset from the pixel centre along `normal`, pixels
  cv::Point2d normal;             // unit gradient direction at the pixel centre
  double magnitude = 0;           // first directional derivative at the zero crossing
  double c1 = 0, c2 = 0, c3 = 0;  // the directional cubic's coefficients
  // Curvature of the isophote through the pixel centre, 1/pixels: -f_tt / |grad f| with t the
  // tangent; positive when the centre of curvature lies on the +normal (light) side.
  double curvature = 0;
};

// Zero crossing of the second directional derivative along the gradient; nullopt when the
// gradient vanishes or the cubic has no maximum of its slope (C3 >= 0).
std::optional<FacetZeroCrossing> facetZeroCrossing(const FacetCoefficients& k);

// The subpixel edge point of pixel `p`, kept only when the zero crossing lies inside the pixel:
// |rho nx| <= maxOffset and |rho ny| <= maxOffset (0.5 = the pixel's square).
std::optional<EdgePoint> facetEdgePoint(const cv::Mat& image, cv::Point p, double maxOffset = 0.5);

}  // namespace facet
