#pragma once
// The lens blur model for benchmark scenes: the optics blur the scene BEFORE the pixel
// integrates it. Rendered by supersampling: the ideal scene on a grid `factor` times finer, a
// Gaussian PSF on that fine grid, then each pixel the mean of its factor x factor fine cells.
// (The scene generator's own render() blurs the integrated pixels instead: the other model.)
// Tiled so that a 1280 x 1024 frame fits in memory.

#include <cstdint>

#include <opencv2/core.hpp>

#include "tests/support/scene/scene.hpp"

namespace facet::bench {

// The scene's primitives and background, blurred with sigma `spec.blurSigma` (pixels) before
// integration, then noise `spec.noiseSigma` and 8-bit quantisation, like Scene::render().
cv::Mat renderLensBlurred(const scene::Scene& scene, int factor = 8);

}  // namespace facet::bench
