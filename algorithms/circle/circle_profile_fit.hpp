#pragma once
// Grey-value refinement of a circle: the maximum-likelihood last step after the geometric fit.
//
// Edge points use one estimate per rim pixel from a 5x5 window; near the Cramer-Rao bound of a
// small circle (r = 10 px, noise 2, contrast 100: about 0.01 px in the centre) that is not
// enough. This fit instead uses every pixel of a band (6 px either side) around the rim and fits
// the grey values directly with the model of a blurred disc,
//   I(x, y) = a(theta) + b(theta) * Phi(-(|p - c| - R) / s),
// where Phi is the standard normal CDF, s the blur (PSF sigma and pixel size combined), b the
// contrast (inside minus outside) and a(x, y) = a0 + g . (p - c0) the outside grey with an
// illumination ramp g. In a thin band a ramp looks much like a shifted rim (it would cost half
// the precision of a small circle), so g is kept only when it is significant (chi-square, 99.9%).
// Levenberg-Marquardt. Before it, pixels whose grey-value gradient the rim cannot explain (a
// tangential gradient, or any gradient away from the rim, beyond 4 standard deviations of its
// noise) and their neighbours leave the band: faint clutter, clutter outside the edge points'
// annulus and the blurred tails of both, which no edge point flags. Tukey weights on the grey
// residuals (from the first step on, 8 robust sigmas once that screen has run) reject the gross
// outliers left, and angular sectors whose residuals stay too large for the noise (the blurred
// tail of a blob next to the rim, each pixel within the Tukey weight's reach) are dropped before
// a final solve.
//
// The 50% level of a blurred disc lies s^2 / (2 R) inside its true rim (the disc is convex, so
// it covers less than half of the PSF centred on its rim); the fitted s corrects that bias
// without any calibration constant.
//
// A sharp image (fitted s below step_profile::kSharpBlur: a lens blur of a third of a pixel or
// less, an exact render) is refitted with each pixel's area in the model (step_profile::
// pixelStep), s then the lens's blur alone: there the pixel's box dominates the profile and the
// Gaussian misfits it by several grey levels at high contrast. `blur` reports the equivalent
// Gaussian sqrt(s^2 + 1/12) either way.

#include <limits>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct CircleProfileFit {
  cv::Point2d centre;   // pixels
  double radius = 0.0;  // pixels, curvature bias corrected
  double blur = 0.0;    // fitted s (the equivalent Gaussian, PSF and pixel together), pixels
  double noise = 0.0;   // robust sigma of the grey residuals, grey levels (8-bit scale)
  int pixels = 0;       // pixels used
  int clipped = 0;      // of them at the sensor's limits, fitted as censored (the model clipped)
  // Only when asked for (fitRimShape), else NaN and zero. The rim's distance from the centre
  // with a second harmonic, in the model's coordinates u (the mapped offsets): |exp(S) u| with
  // S = [[a, c], [c, -a]], an ellipse close to the fitted circle. `secondHarmonic`: the score
  // test of (a, c) at this fit, chi-square with 2 degrees of freedom; `shapeStep`: their
  // Gauss-Newton step (a, c) with the other parameters fitted along; `shapeInformation`: the
  // inverse of that step's covariance (a Wald test of a shape v: v^T shapeInformation v).
  double secondHarmonic = std::numeric_limits<double>::quiet_NaN();
  cv::Vec2d shapeStep{0.0, 0.0};
  cv::Matx22d shapeInformation = cv::Matx22d::zeros();
};

// `image`: CV_8UC1 or CV_16UC1. `centre`, `radius`: the geometric fit of the edge points.
// `rimPoints`: its inlier edge points; only the parts of the rim they cover are used (occluded or
// cluttered sectors stay out). `foreignPoints`: edge points that are not the rim (clutter, an
// occluder's border); pixels within 2 px of them stay out, and up to 4 px where a strong edge's
// blurred step still reaches a quarter of the noise. `noiseSigma` (grey levels, 8-bit scale;
// 0 = unknown) lets a clean, large rim use only the share of its pixels the precision needs.
// Returns nothing when the fit does not converge to a plausible circle (moves farther than
// `maxShift` pixels, blur outside (0.2, 5) px).
//
// Pixels at the sensor's limits (255 or 0 in an 8-bit image, 65535 or 0 in a 16-bit one) are
// censored observations: the model is clipped there as the sensor clips (an overexposed
// backlight's step is fitted with its levels beyond the clip). When the step's middle itself lies
// beyond the limit, nothing is returned: the rim would be extrapolated, not measured.
//
// An elliptic rim (rim_ellipse.hpp): `toCircle` maps offsets from the centre so that the rim
// becomes a circle of `radius` (Ellipse::toCircle, area-preserving), and the model applies to
// the mapped offsets. The centre comes back in the image; the radius is the mapped circle's, the
// radius of the circle of the rim's area. The map changes the blur across the rim by the square
// root of the axes' ratio either way (4% at axes 0.92 apart): a second harmonic around the rim,
// which leaves the centre alone. Identity (the default): a circle, as above.
//
// `fitRimShape`: also test the fitted rim for a second harmonic and give the step that fits it
// (CircleProfileFit::secondHarmonic, shapeStep): the grey values' own judgement of whether the
// rim is an ellipse, and of which, far more sensitive than the edge points' (the pixels near the
// rim weigh in) and blind to the pixels screened out as clutter. One more pass over the band.
std::optional<CircleProfileFit> fitCircleProfile(const cv::Mat& image, cv::Point2d centre,
                                                 double radius,
                                                 const std::vector<cv::Point2d>& rimPoints,
                                                 const std::vector<EdgePoint>& foreignPoints = {},
                                                 double noiseSigma = 0.0, double maxShift = 1.0,
                                                 const cv::Matx22d& toCircle = cv::Matx22d::eye(),
                                                 bool fitRimShape = false);

}  // namespace facet
