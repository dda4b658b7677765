#pragma once
// Tabulated edge profiles for edge_profile_fit (internal to algorithms/edges): the standard
// normal CDF and PDF, and per PSF sigma and blur model the exact profile of a blurred step
// integrated over the pixel square, for normal angles 0..45 degrees in 1 degree steps.

#include <memory>

#include <opencv2/core.hpp>

namespace facet::edge_profile {

// Value and slope of the profile P and of its derivative D on one table interval.
struct alignas(16) ProfileInterval {
  float cdf, cdfSlope, pdf, pdfSlope;
};

// A tabulated edge profile: value P and derivative D per interval (value and slope), looked up
// at table coordinate (u * coordScale + range) * perUnit for the distance u to the edge line.
struct ProfileView {
  const ProfileInterval* data = nullptr;
  int size = 0;
  float coordScale = 1, range = 0, perUnit = 1;
  double derivScale = 1;  // D * derivScale = dP/du * (1 / coordScale) convention, see step()
};

// The erf profile of width w (pixels).
ProfileView erfView(double w);

// The exact profiles for one PSF sigma (pixels) and blur model (true = Gaussian on the sampled
// image, false = before pixel integration), cached; rows are built on first use per angle.
class ApertureProfiles;
std::shared_ptr<ApertureProfiles> apertureProfiles(double sigma, bool gridBlur);
// The row for a normal's angle: the nearest whole degree, or with degreeStep > 1 the nearest
// multiple of degreeStep degrees (fewer rows to build, for the blur search; see fitBlurModel).
ProfileView apertureView(ApertureProfiles& profiles, cv::Point2d normal, int degreeStep = 1);

}  // namespace facet::edge_profile
