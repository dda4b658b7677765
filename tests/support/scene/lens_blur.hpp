#pragma once
// Lens blur for test scenes: the Gaussian PSF acts on the continuous scene before the pixel
// integrates it, so a pixel's value is the scene convolved with K = G_sigma * box (the unit pixel
// square), which is separable in x and y.
//
// How: the scene is painted on a grid `lensSupersampling` times finer than the image (coverage
// exact in x, 256 sub-scanlines per fine row in y), and each fine cell is weighted by
// the exact integral of K over the cell, from the antiderivative of K
//   C(u) = sigma [g((u + 1/2) / sigma) - g((u - 1/2) / sigma)],  g(x) = x Phi(x) + phi(x).
// That is exact for a scene constant within each fine cell; a cell cut by an edge counts with its
// mean grey, which widens the blur symmetrically about the edge by at most h^2/4 in variance
// (h = 1/scale pixels) and so does not move a straight edge (tests/scene checks the result
// against the closed form of a straight edge). The scene beyond the image border is painted too,
// since the PSF reaches across it: there is no border rule. Rendering goes in bands of rows, so
// memory stays a few tens of MB.

#include <vector>

#include <opencv2/core.hpp>

#include "tests/support/scene/scene.hpp"

namespace facet::scene {

// The noise-free image (before illumination gradient, noise and quantisation), doubles on the
// 8-bit scale, with spec.blurSigma > 0 acting as a lens PSF.
cv::Mat renderLensBlurred(const std::vector<Primitive>& primitives, const SceneSpec& spec);

// The value of a pixel centred at distance u (pixels, along the normal) from a straight step edge
// from 0 to 1, for an axis-aligned edge: the closed form C(u) above.
double lensStepProfile(double u, double sigma);

}  // namespace facet::scene
