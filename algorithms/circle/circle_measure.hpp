#pragma once
// CircleMeasure: robust subpixel measurement of one circle (hole, bore, round part) in an annulus
// around its expected position.
//
// Pipeline (seed dissertation, part 2):
//   1. annulus [radius - width, radius + width] around the expected centre;
//   2. Canny inside the annulus, both hysteresis thresholds chosen from that annulus alone
//      (annulus_edges.hpp);
//   3. subpixel Facet-model edge points (algorithms/edges);
//   4. outliers removed by gradient direction: near-radial within a tolerance, expected polarity;
//   5. RANSAC circle (an inlier lies near the hypothesis AND its gradient is radial to it within
//      12 degrees, so a straight edge next to an occluded sector cannot lend a wrong circle its
//      points; a short run of inliers that a fit of the others puts more than the RANSAC
//      threshold off is dropped too), then a geometric (orthogonal distance) least-squares fit
//      on the inliers by Levenberg-Marquardt, optionally with a robust Huber/Tukey weight
//      (IRLS); the curvature bias of second-derivative edges (-k / r) is corrected with a
//      measured k;
//   6. (default) a grey-value refinement on the rim the inliers cover (circle_profile_fit.hpp):
//      a blurred-disc model fitted to every pixel of a band around the rim. It reaches the
//      Cramer-Rao bound where edge points stay about 2x above it (small circles) and corrects the
//      curvature bias from the fitted blur instead of a constant. Angular sectors whose grey
//      residuals are too large for the noise (faint clutter near the rim) are dropped and the
//      fit repeated. Pixels the sensor clipped (an overexposed backlight) are fitted as
//      censored (censored_pixels.hpp); a clipped rim the grey values cannot fit (its step's
//      middle beyond the clip) is refused, its edge points alone being up to a pixel off.
//   5b. (default) when an ellipse explains the rim's points significantly better than the circle
//      and takes in at least its inliers (a tilted view: rim_ellipse.hpp), the rim is that
//      ellipse; step 6 then fits the blurred disc in the coordinates that make it a circle and
//      refits the ellipse's shape to the grey values too. With a sector of the rim hidden (under
//      300 degrees of it visible) the edge points alone cannot tell such an ellipse from a circle
//      with clutter beside it: step 6 judges, its circle's grey fit testing for a second
//      harmonic (an ellipse) and the ellipse then fitted there; a rim whose grey values are not
//      a circle's and whose ellipse cannot be fitted (or is flatter than a 60 degree view, or
//      leaves the annulus) is refused (FitTooPoor).
// RMS, roundness, inliers and coverage always describe the edge points of step 5 (5b): those of
// the ellipse when the rim is one.
//
// Failures are reported as a cause and a message (Status<CircleFailure>), never as a bogus
// circle: when `status.ok()` is false the centre, radius and diameter are NaN.
//
// Coordinates: x right, y down, centre of pixel (0,0) at (0,0). Lengths in pixels.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

// Grey-value change when crossing the circle from its inside to its outside.
enum class CirclePolarity {
  DarkToLight,  // dark inside, light outside (a dark disc on a light background, a dark hole)
  LightToDark,  // light inside, dark outside (a bright disc, a backlit hole)
  Any,          // either, as long as all inliers agree with the circle (the fit decides)
};

// Weight of the final least-squares fit (iteratively reweighted).
enum class CircleRobustWeight {
  None,   // plain least squares
  Huber,  // Huber weight, tuning constant 1.345 sigma
  Tukey,  // Tukey biweight, tuning constant 4.685 sigma
};

struct CircleMeasureParams {
  // Expected centre, image pixels (from a shape match or the recipe). No default: must be set.
  cv::Point2d centre{-1.0, -1.0};
  // Nominal radius, pixels (> 0). No default: must be set.
  double radius = 0.0;
  // Half-width of the search annulus, pixels: edges are searched at distances
  // [radius - width, radius + width] from `centre`. It must cover the coarse position error plus
  // the radius tolerance. Default 5.
  double width = 5.0;
  // Expected polarity of the rim. Default Any.
  CirclePolarity polarity = CirclePolarity::Any;
  // Maximum angle between an edge point's gradient and the radial direction from `centre`,
  // degrees. Default 25 (a coarse centre off by 2 px tilts the normals of an r = 10 circle by
  // about 12 degrees).
  double directionToleranceDeg = 25.0;
  // Hysteresis thresholds of Canny, grey levels per pixel (8-bit scale). Unset (default): both
  // are chosen automatically from the annulus alone.
  std::optional<double> cannyLow;
  std::optional<double> cannyHigh;
  // RANSAC inlier threshold on the orthogonal distance to the circle, pixels. Default 0.5.
  double ransacThreshold = 0.5;
  // Minimum number of inliers of the final fit. Default 12.
  int minInliers = 12;
  // Minimum angular coverage of the inliers, degrees (0..360). Partial arcs down to this extent
  // are measured. Default 120 (a rim one third hidden still measures).
  double minCoverageDeg = 120.0;
  // Robust weight of the geometric fit. Default Tukey.
  CircleRobustWeight robustWeight = CircleRobustWeight::Tukey;
  // Largest acceptable RMS of the inliers' orthogonal residuals, pixels. Default 0.5.
  double maxRms = 0.5;
  // Final grey-value refinement (circle_profile_fit.hpp): fits a blurred-disc model to every
  // pixel of a band around the rim where the inliers lie; reaches the Cramer-Rao bound of small
  // circles and corrects the curvature bias from the fitted blur. Default on.
  bool refineWithGreyValues = true;
  // Without the grey-value refinement (or when it fails): correct the radial bias of
  // second-derivative edges on a curved, blurred rim, which puts the fitted radius about
  // radiusBiasK / radius pixels too small. Default on.
  bool correctRadiusBias = true;
  // A rim the image shows as an ellipse (a round feature on a plane viewed at a tilt, off the
  // lens's axis, or an oval part) is measured as that ellipse when one explains the rim's edge
  // points significantly better than a circle (rim_ellipse.hpp), or the circle's grey-value fit
  // finds the ellipse's second harmonic. Off: always a circle, whose robust fit keeps only the
  // arcs one circle matches on such a rim, and no grey-value test of the shape. Default on.
  bool measureEllipticRims = true;
  // Curvature-bias constant k of the edge-point fit, pixels^2 (bias = -k / r). The default was
  // measured with the Facet 5x5 operator on discs blurred with a Gaussian PSF of sigma 1 px
  // (bench_circle --no-grey-refinement --no-bias-correction prints it); it grows with the blur
  // variance of the optics (about (sigma^2 + 1.2) / 2).
  double radiusBiasK = 1.1;
};

// Why a circle was not measured, most fundamental first: a measurement stops at the first.
enum class CircleFailure {
  None,                 // measured
  BadInput,             // empty image, wrong type, radius <= 0, width <= 0, NaN, ...
  AnnulusOutsideImage,  // the search annulus does not lie (enough) inside the image
  TooFewPoints,         // fewer than minInliers edge points / inliers
  CoverageTooSmall,     // inliers cover less than minCoverageDeg
  FitTooPoor,           // RMS of the inliers above maxRms, or the fit did not converge
};

// Machine-readable snake_case name of a cause ("too_few_points", ...); "" for None.
[[nodiscard]] std::string_view toString(CircleFailure failure);

struct CircleMeasurement {
  cv::Point2d centre{};    // pixels; NaN when !status.ok()
  double radius = 0.0;     // pixels; NaN when !status.ok()
  double diameter = 0.0;   // pixels; NaN when !status.ok()
  double roundness = 0.0;  // max minus min signed radial deviation of the inliers, pixels
  double rms = 0.0;    // RMS of the inliers' orthogonal residuals (to the ellipse if elliptic), px
  int edgePoints = 0;  // subpixel edge points found in the annulus
  int candidates = 0;  // edge points left after the gradient-direction test
  int inliers = 0;     // inliers of the final fit
  double coverageDeg = 0.0;  // angular extent covered by the inliers, degrees
  // The rim was measured as an ellipse (measureEllipticRims): the centre is the ellipse's, the
  // radius that of the circle of its area (the axes' geometric mean), the roundness about the
  // axes' difference. A round feature seen at a tilt in an uncalibrated view: its centre is
  // right, its size is not one diameter (calibrate the measuring plane for millimetres).
  bool elliptic = false;
  double majorDiameter = 0.0;  // pixels; the diameter when the rim is a circle
  double minorDiameter = 0.0;
  double majorAxisDeg = 0.0;  // of the major axis, degrees counter-clockwise on screen, [0, 180)
  bool greyRefined = false;   // centre and radius come from the grey-value refinement
  double blur = 0.0;          // blur fitted by the grey-value refinement, pixels (0 without)
  // Share of the pixels within 3 px of the rim at the sensor's limits (the image type's largest
  // value, or 0): an overexposed backlight, say. The grey-value refinement fits such a rim with
  // its step clipped as the sensor clips it; without that fit its edge points lie up to a pixel
  // off towards the unclipped side, so a clipped rim the grey values could not fit is refused.
  double clippedShare = 0.0;
  double lowThreshold = 0.0;  // Canny thresholds actually used
  double highThreshold = 0.0;
  std::vector<cv::Point2d> inlierPoints;  // subpixel edge points of the fit, for display
  // What a measurement of the same rim in another geometry (the measuring plane) needs: every
  // subpixel edge point found in the annulus, the rim's polarity (+1: the grey rises outwards,
  // dark inside; -1: it falls) and the annulus's noise level (grey levels, 8-bit scale).
  std::vector<EdgePoint> annulusEdges;
  int rimSign = 0;
  double noiseSigma = 0.0;

  Status<CircleFailure> status;  // NaN centre, radius and diameter when !ok()
};

// The share of the pixels near a rim at the sensor's limits (CircleMeasurement::clippedShare)
// beyond which the sensor clipped the rim: an overexposed backlight fills about a third (its
// light side at the clip); noise alone puts a rim a few grey levels below the clip there in a
// pixel or two of a hundred.
inline constexpr double kClippedRimShare = 0.05;

// Why a measurement's circle cannot stand without a grey-value fit of its rim: the sensor
// clipped the rim (clippedShare beyond kClippedRimShare), so its edge points lie up to a pixel
// off towards the unclipped side. Empty when it can. `depth`: the image's (CV_8U or CV_16U).
[[nodiscard]] std::string clippedRimRefusal(const CircleMeasurement& m, int depth);

// Measures one circle in an 8-bit or 16-bit single-channel image. Never throws for bad input:
// the result's status carries BadInput and a message instead.
CircleMeasurement measureCircle(const cv::Mat& image, const CircleMeasureParams& params);

}  // namespace facet
