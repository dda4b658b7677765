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
  double halfAcross = 5.0;        // pixels either side of the edge line taken into the fit
  double halfAlong = 6.0;         // pixels either side of the point along the edge (straight edges)
  double minAlong = 2.0;          // shortest half-length on tight curves (see profileHalfAlong)
  double maxCurvatureBias = 0.1;  // pixels
  int iterations = 2;             // Gauss-Newton iterations
  // Profile width w in pixels (sigma of the blur including the pixel aperture); 0 = fit it per
  // point (slower, a little more noise). detectSubpixelEdges estimates one width per image with
  // estimateEdgeWidth and passes it here.
  double width = 0.0;
  double initialWidth = 1.2;  // pixels, starting value when the width is fitted
  // With a known width the profile is tabulated exactly for the pixel aperture at the point's
  // normal angle. Where the blur acts: true = on the sampled image, as a discrete Gaussian kernel
  // (the image formation of tests/support/scene, and of any blur filter applied after
  // sampling); false = a continuous Gaussian PSF before pixel integration (a lens). The two
  // differ by up to 0.03 of the contrast at sigma 0.5-0.8 (0.03 px in position), vanishing as
  // sigma grows. detectSubpixelEdges chooses it per image with estimateEdgeBlur.
  bool blurOnPixelGrid = false;
};

// Refines the edge near pixel `pixel` of a CV_8UC1 / CV_16UC1 image, starting from the unit
// normal `normal` and the offset `offset` (pixels along the normal from the pixel centre).
// Near the image's border the window keeps the pixels inside the image (the caller checks that
// both sides of the edge are in it, as detectSubpixelEdges does). Returns the foot
// of the pixel centre on the fitted edge line, the fitted normal and the slope at the edge
// (b / (w sqrt(2 pi))), or nullopt when the fit degenerates. `fittedWidth`, when given, receives w.
std::optional<EdgePoint> fitEdgeProfile(const cv::Mat& image, cv::Point pixel, cv::Point2d normal,
                                        double offset, const EdgeProfileParams& params = {},
                                        double* fittedWidth = nullptr);

// On a curved edge the straight-line fit returns the arc's mean offset over its window,
// kappa <t^2> / 2, which for the window +-L along the edge is about kappa L (L + 1) / 6 pixels
// towards the centre of curvature. To keep that bias small on tight curves the window is
// shortened to L = sqrt(6 maxCurvatureBias / |kappa|), within [minAlong, halfAlong].
double profileHalfAlong(double curvature, const EdgeProfileParams& params = {});
// The fit's offset towards the centre of curvature per unit curvature, for the window of
// `params` (pixels^2): <t^2> / 2 = L^2 / 6 with L = halfAlong (t spread evenly over +-L).
double profileWindowBias(const EdgeProfileParams& params = {});

// The window radius (pixels) the fit reads around its pixel.
int edgeProfileReach(const EdgeProfileParams& params = {});

struct EdgeSeed {
  cv::Point pixel;
  cv::Point2d normal;
  double offset = 0;
};
// The blur of an image's edges: profile width (EdgeProfileParams::width) and where the blur acts
// (EdgeProfileParams::blurOnPixelGrid).
struct EdgeBlur {
  double width = 0;
  bool onPixelGrid = false;
};
// One blur for an image, from up to `maxSamples` of the given seeds (pixel, facet normal, facet
// offset), spread evenly over the list: the median of their fitted erf widths gives a first
// width; then both blur models' exact profiles, at sigmas around it, are fitted to up to 16 of
// those seeds (the quarter that fits a straight step worst left out) and the model and sigma with
// the least residual win. So the default needs no knowledge of how the images were formed. Returns
// `params.initialWidth` and `params.blurOnPixelGrid` when no fit succeeds.
// `onlyModel` restricts the search to one model (true = pixel grid, false = lens).
EdgeBlur estimateEdgeBlur(const cv::Mat& image, const std::vector<EdgeSeed>& seeds,
                          const EdgeProfileParams& params = {}, int maxSamples = 64,
                          std::optional<bool> onlyModel = std::nullopt);
// estimateEdgeBlur(...).width.
double estimateEdgeWidth(const cv::Mat& image, const std::vector<EdgeSeed>& seeds,
                         const EdgeProfileParams& params = {}, int maxSamples = 64);

}  // namespace facet
