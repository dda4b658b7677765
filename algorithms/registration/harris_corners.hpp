#pragma once
// Multi-scale Harris corners with a per-image budget and spatial spreading.
//
// The image is searched on a pyramid with `levelsPerOctave` levels per octave (Gaussian
// pre-smoothing, no aliasing); at each level the Harris measure det(M) - k trace(M)^2 of the
// scale-normalised second-moment matrix M is thresholded and its 3x3 local maxima kept. The
// strongest corners are then thinned by adaptive non-maximal suppression (Brown, Szeliski and
// Winder 2005): each corner's suppression radius is its distance to the nearest clearly
// stronger corner, and the `maxCorners` with the largest radii are kept, which spreads them
// over the image instead of clustering them on the most textured part.

#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct HarrisParams {
  int maxCorners = 500;           // per-image budget after spreading
  int octaves = 5;                // pyramid octaves searched (image halves per octave)
  int levelsPerOctave = 2;        // scale levels per octave (sqrt(2) steps)
  double derivationSigma = 1.0;   // pixels at the level; Gaussian of the derivatives
  double integrationSigma = 2.0;  // pixels at the level; Gaussian window of M
  double k = 0.04;                // Harris constant
  // Corners weaker than this fraction of the strongest response at their level are dropped.
  double relativeThreshold = 1e-3;
  // Minimum absolute response (on images scaled to [0, 1]): flat images yield no corners.
  double absoluteThreshold = 1e-8;
  // Harris-Laplace: keep a corner only at scales where |Laplacian| is not smaller than at the
  // neighbouring scales (one characteristic scale per structure). Off: every scale's corners.
  bool selectScale = true;
  // ... within this factor: |Laplacian| at least scalePlateau times the neighbours'. Where
  // straight edges meet (a drawing, a machined part) the corner has no characteristic scale: its
  // scale-normalised Laplacian s^2 C / (s^2 + b^2) is flat but for the camera's blur b, which
  // makes it rise with s, so a strict maximum drops it from the finest levels of a sharp image
  // (a logo: 14 corners, 37 once blurred). A lens of b = 0.7 px (a sharp one) raises it by
  // 2 (2 + b^2) / (4 + b^2) = 1.11 from the finest level (s = 1.41) to the next (s = 2): 1/1.11.
  // 1 = a strict maximum.
  double scalePlateau = 0.9;
  int border = 16;              // pixels at the level; corners closer to the edge are dropped
  double anmsRobustness = 0.9;  // a neighbour suppresses when response * this > own response
};

struct HarrisCorner {
  cv::Point2d pt;         // subpixel position in full-resolution pixels
  double scale = 1.0;     // characteristic scale: integration sigma in full-resolution pixels
  double response = 0.0;  // Harris measure at the level
  int level = 0;          // pyramid level index (0 = full resolution)
};

// `grey` is CV_32F scaled to [0, 1]. Returns at most params.maxCorners corners.
std::vector<HarrisCorner> detectHarrisCorners(const cv::Mat& grey, const HarrisParams& params = {});

// Single-scale Harris points spread on a grid: in every `cell` x `cell` block the strongest
// response (above the thresholds of `params`) at the finest scale. Dense and even, for
// re-matching around a known transform. Uses derivationSigma, integrationSigma, k, thresholds
// and border of `params`.
std::vector<HarrisCorner> detectHarrisGrid(const cv::Mat& grey, int cell,
                                           const HarrisParams& params = {});

// The corner detection keeps its images with the calling thread from call to call (a large
// frame's pages are then not faulted in afresh each time), up to kKeptImageBytes; larger
// detections allocate what goes beyond. What the calling thread keeps now, in bytes.
inline constexpr std::size_t kKeptImageBytes = std::size_t{256} << 20;
std::size_t keptCornerImageBytes();

// Adaptive non-maximal suppression: keeps `count` corners with the largest suppression radii.
std::vector<HarrisCorner> spreadCorners(const std::vector<HarrisCorner>& corners, int count,
                                        double robustness = 0.9);

}  // namespace facet
