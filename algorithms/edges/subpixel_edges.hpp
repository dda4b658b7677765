#pragma once
// Subpixel edge points from Haralick's cubic facet model.
//
// Each pixel's 5x5 neighbourhood is fitted with a bicubic polynomial through fixed convolution
// kernels; along the gradient direction the second directional derivative's zero crossing gives
// the subpixel edge position, kept when it lies inside the pixel. Candidate pixels come from
// Canny with hysteresis (canny.hpp), whose thresholds may be chosen automatically
// (auto_thresholds.hpp).
//
// Coordinates: x right, y down, centre of pixel (0,0) at (0,0).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct EdgePoint {
  cv::Point2d position;  // subpixel position, image pixels
  cv::Point2d normal;    // unit gradient direction (dark -> light), image axes
  double magnitude = 0;  // gradient magnitude, grey levels per pixel (8-bit scale for 16-bit
                         // input divided by 256)
};

struct EdgeParams {
  // Hysteresis thresholds on the gradient magnitude (grey levels per pixel). When either is
  // missing, both are chosen automatically from the region's gradient histogram.
  std::optional<double> low;
  std::optional<double> high;
  // Region of interest in image pixels; empty = the whole image.
  cv::Rect roi;
  // Optional 8-bit mask: only non-zero pixels may be edge pixels. Either of the image's size, or
  // of `roi`'s size and covering `roi` (cheap when many small regions of a large image are
  // searched).
  cv::Mat mask;
  // Link points into contours (EdgeContours::contours); off saves time when only points are needed.
  bool linkContours = false;
  // Correct the systematic radial bias of the edges on curved contours (about -k/r pixels for
  // curvature radius r, k growing with the blur; curvature_bias.hpp); uses the local curvature
  // along the linked contours.
  bool correctCurvatureBias = false;
  // Refine each facet point by fitting a blurred-step model over a 7x7 px window along the edge
  // (edge_profile_fit.hpp): removes the cubic facet's shape bias and averages noise along the
  // edge. Off gives the plain facet zero crossings. Near the image border the window is cut to
  // the image; a point whose edge has less than two profile widths (2 px at least) of image on
  // either side, across it, keeps its facet position.
  bool fitProfile = true;
  // Near the image border (above): false keeps the facet position of every point whose full
  // window would leave the image, as before the window was cut to the image.
  bool fitAtImageBorder = true;
  // Optional 8-bit mask of the image's or of `roi`'s size (like `mask`): only points whose pixel
  // is non-zero there are refined by the profile fit; the others keep their facet position. The
  // blur is still estimated from all the edges, so the points fitted are the same as without it
  // (up to the curvature correction of points within 8 points along a contour of an unfitted
  // one). For a caller that needs precise points only in part of the region (shape refinement).
  cv::Mat fitMask;
  // Where the blur acts, for the profile fit: true = on the sampled image (a blur filter run
  // after sampling), false = before pixel integration (a lens). Unset (default): chosen per image
  // from the edges' profiles (estimateEdgeBlur), so neither has to be known.
  std::optional<bool> blurOnPixelGrid;
  // Edge points fitted with a free width to estimate the blur (estimateEdgeBlur). Fewer suffice
  // where many small regions of one image are searched and each only needs its local width.
  int blurSamples = 64;
};

struct EdgeContours {
  std::vector<EdgePoint> points;
  // Each contour lists indices into `points`, in order along the edge (filled when linkContours).
  std::vector<std::vector<int>> contours;
  // Blur (Gaussian sigma, pixels, without the pixel aperture) estimated from the edges' profiles;
  // 0 when the profile fit is off or there were no edges.
  double blurSigma = 0;
  // Where that blur acted, as the profiles tell: true = on the sampled image (a blur filter),
  // false = before pixel integration (a lens); see EdgeProfileParams::blurOnPixelGrid.
  bool blurOnPixelGrid = false;
  double lowThreshold = 0;  // thresholds actually used
  double highThreshold = 0;
};

// Subpixel edges of an 8-bit or 16-bit single-channel image. An empty image gives no points;
// any other type (colour, float, ...) or a mask of the wrong size/type throws
// std::invalid_argument.
EdgeContours detectSubpixelEdges(const cv::Mat& image, const EdgeParams& params = {});

}  // namespace facet
