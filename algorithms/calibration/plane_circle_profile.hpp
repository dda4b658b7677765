#pragma once
// Grey-value refinement of a circle in the measuring plane: circle_profile_fit's blurred-disc
// model with the circle in the plane and the blur in the image.
//
// Why: a round hole on a tilted plane, or seen through a distorting lens, is no circle in the
// image. The image's grey-value fit (facet's most precise circle) fits a circle to it, so its
// centre is not the image of the hole's centre and its radius no radius of the hole; mapping its
// edge points into the plane keeps the edge points' noise (2-4x the grey fit's on small rims).
// Resampling the plane square-on and fitting there cannot carry an image sharper than the
// resampling assumes. This fit instead models every pixel of a band around the rim where it is:
//   I(p) = a0 + g . (p - p0) + b * Phi(-d(p) / s),   d(p) = (|W(p) - C| - R) / k(p),
// W the image-to-plane mapping (plane_patch.hpp), C and R the circle in the plane (mm), d the
// pixel's distance from the rim in image pixels (k: the plane's mm per image pixel along the
// rim's normal there), s the blur in the image (PSF and pixel together), b the contrast, a0 and
// g the outside grey and its illumination ramp in the image. Nothing is resampled; the lens and
// the view enter only through W.
//
// The band, the screens against foreign edges and gradients, the ramp's significance test and
// the contaminated-sector refit are those of fitCircleProfile. Two differences: the robust
// weights are set again at every step (weights frozen at the start's residuals kept radii on the
// demo recordings 0.012 px towards the start), and a big rim keeps four times the pixels the
// image fit keeps (its diameter 1.5x better at r = 29 px; 1.5 ms for such a circle here).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"
#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

// Where an image point lies against a circle in the plane: its signed distance from the rim in
// image pixels (positive outside), the plane's mm per image pixel across the rim there, and the
// rim's outward normal in the plane and in the image (unit vectors). `offset`: the point's plane
// place minus the circle's centre; `alongX`, `alongY`: the plane's derivatives at the point along
// the image's axes (mm per pixel).
struct RimGeometry {
  double distance = 0.0, scale = 0.0;
  cv::Point2d planeNormal, imageNormal;
};
RimGeometry rimGeometry(cv::Point2d offset, cv::Point2d alongX, cv::Point2d alongY,
                        double radiusMm);

struct PlaneCircleProfileFit {
  cv::Point2d centreMm;
  double radiusMm = 0.0;  // curvature bias corrected
  double blur = 0.0;      // fitted s, image pixels
  double noise = 0.0;     // robust sigma of the grey residuals, grey levels (8-bit scale)
  int pixels = 0;         // pixels used
};

// `image`: CV_8UC1 or CV_16UC1. `centreMm`, `radiusMm`: a start in the plane (the rim's edge
// points fitted there). `rimPoints`: those edge points in the image; only the parts of the rim
// they cover take part. `foreignPoints`, `noiseSigma`: as fitCircleProfile's. Nothing when the
// fit does not converge to a plausible circle (centre or radius moved by more than `maxShiftPx`
// image pixels, blur outside (0.2, 5) px, contrast below 4 noise levels) or the band leaves the
// plane or the image.
std::optional<PlaneCircleProfileFit> fitPlaneCircleProfile(
    const cv::Mat& image, const WorldMapping& plane, cv::Point2d centreMm, double radiusMm,
    const std::vector<cv::Point2d>& rimPoints, const std::vector<EdgePoint>& foreignPoints = {},
    double noiseSigma = 0.0, double maxShiftPx = 1.0);

}  // namespace facet
