#pragma once
// Refinement of a facet edge point by fitting a blurred-step model to the pixels around it.
//
// Why: the cubic facet's zero crossing is biased against a blurred step (a cubic is the wrong
// shape for an erf profile, and the 5x5 square window samples an oblique edge asymmetrically),
// by up to 0.06 px depending on orientation and subpixel phase, and its 25 pixels average too
// little noise (0.04-0.08 px at noise sigma 2, contrast 100). An optical edge is a step blurred
// by the lens PSF and integrated over the pixel area; locally straight it reads
//   I(p) = a + b * Phi(((p - c) . n - e) / w)
// with Phi the standard normal CDF, background a, contrast b, offset e along the unit normal n
// and width w (PSF sigma and pixel aperture combined). The pixel aperture makes the true profile
// the erf convolved with the pixel's projection onto n, which is symmetric like the erf, so the
// centre of the fit is unbiased while the width absorbs the aperture.
//
// The fit takes the pixels within `halfAcross` of the facet's edge line and within `halfAlong`
// along it and runs Gauss-Newton on (a, b, e) -- plus w when the width is not given -- using the
// linearised basis 1, Phi(z), phi(z) [, z phi(z)] with z = u / w: every iteration is one small
// linear least-squares solve. A last step fits the turn of the normal (basis t phi(z)), which is
// odd along the edge and hence independent of the other parameters. A wide window across the
// edge (default +-5 px) is what separates the offset from the background level; the length along
// the edge (+-5 px) sets the noise averaging.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct EdgeProfileParams {
  double halfAcross = 5.0;  // pixels either side of the edge line taken into the fit
  double halfAlong = 5.0;   // pixels either side of the point along the edge
  int iterations = 1;       // Gauss-Newton iterations
  // Profile width w in pixels (sigma of the blur including the pixel aperture); 0 = fit it per
  // point (slower, a little more noise). detectSubpixelEdges estimates one width per image with
  // estimateEdgeWidth and passes it here.
  double width = 0.0;
  double initialWidth = 1.2;  // pixels, starting value when the width is fitted
};

// Refines the edge near pixel `pixel` of a CV_8UC1 / CV_16UC1 image, starting from the unit
// normal `normal` and the offset `offset` (pixels along the normal from the pixel centre).
// The pixel must lie at least edgeProfileReach(params) pixels inside the image. Returns the foot
// of the pixel centre on the fitted edge line, the fitted normal and the slope at the edge
// (b / (w sqrt(2 pi))), or nullopt when the fit degenerates. `fittedWidth`, when given, receives w.
std::optional<EdgePoint> fitEdgeProfile(const cv::Mat& image, cv::Point pixel, cv::Point2d normal,
                                        double offset, const EdgeProfileParams& params = {},
                                        double* fittedWidth = nullptr);

// The window radius (pixels) the fit reads around its pixel.
int edgeProfileReach(const EdgeProfileParams& params = {});

// One profile width for an image: the median of per-point fitted widths over up to `maxSamples`
// of the given seeds (pixel, facet normal, facet offset), spread evenly over the list. Returns
// `params.initialWidth` when no fit succeeds.
struct EdgeSeed {
  cv::Point pixel;
  cv::Point2d normal;
  double offset = 0;
};
double estimateEdgeWidth(const cv::Mat& image, const std::vector<EdgeSeed>& seeds,
                         const EdgeProfileParams& params = {}, int maxSamples = 64);

}  // namespace facet
