#pragma once
// Coarse location of a round mark (fiducial, hole) near an expected position, before the
// subpixel measurement of measureCircle(): normalised cross-correlation with an antialiased disc
// of the nominal radius, inside a search window. Good to about a pixel, which is what the
// measurement's annulus needs.

#include <optional>

#include <opencv2/core.hpp>

#include "algorithms/circle/circle_measure.hpp"

namespace facet {

struct DiscSearch {
  cv::Point2d expected;     // expected centre, pixels
  double radius = 0;        // nominal radius, pixels (> 1)
  double searchRadius = 0;  // the centre may be this far from `expected`, pixels
  CirclePolarity polarity = CirclePolarity::Any;  // DarkToLight: dark disc on light surround
  double minScore = 0.5;                          // minimum normalised correlation, 0..1
};

struct DiscLocation {
  cv::Point2d centre;  // pixel-accurate centre
  double score = 0;    // normalised correlation of the best position
};

// The best disc position within the search radius, or nothing when no position reaches
// minScore (or the window lies outside the image). `image`: 8- or 16-bit single channel.
std::optional<DiscLocation> locateDisc(const cv::Mat& image, const DiscSearch& search);

}  // namespace facet
