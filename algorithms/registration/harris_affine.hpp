#pragma once
// Harris-Affine regions (Mikolajczyk and Schmid 2004): a Harris corner with its characteristic
// scale (selected by the Laplacian in detectHarrisCorners) and an elliptical shape found by
// iterating the second-moment matrix to isotropy. Simplification: the point and the scale are
// not re-estimated during the shape iterations; the NCC's ring shifts absorb the scale drift. The
// ellipse's shape matrix maps the unit circle to the region, so sampling a log-polar window through
// it normalises the region to a circle: an affine change of view then leaves only a rotation (a
// cyclic angle shift).

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/registration/harris_corners.hpp"

namespace facet {

struct HarrisAffineParams {
  int maxIterations = 6;  // shape adaptation iterations
  double isotropyRatio =
      0.95;  // stop when min/max eigenvalue of M in the normalised frame exceeds it
  double maxAnisotropy = 6.0;  // regions more elongated than this are rejected
  int patchRadius = 12;        // pixels of the normalised patch on which M is measured
};

struct AffineRegion {
  cv::Point2d pt;                          // centre, full-resolution pixels
  cv::Matx22d shape = cv::Matx22d::eye();  // unit circle -> region offsets (pixels); includes scale
  double response = 0.0;
};

// Plain corners as circular regions (shape = scale * identity).
std::vector<AffineRegion> circularRegions(const std::vector<HarrisCorner>& corners);

// Adapts each corner's scale and shape; corners whose adaptation diverges are dropped.
// `pyramid` comes from buildSamplingPyramid.
std::vector<AffineRegion> adaptAffineRegions(const std::vector<cv::Mat>& pyramid,
                                             const std::vector<HarrisCorner>& corners,
                                             const HarrisAffineParams& params = {});

}  // namespace facet
