#pragma once
// The matches that agree on the rotation and scale most of them share.

#include <vector>

#include "algorithms/registration/register_images.hpp"

namespace facet {

// Each match carries its own rotation and scale (FeatureMatch::rotationDeg, ::scale). The
// dominant pair is the peak of a joint histogram of rotation (10 degree bins) and log2 scale
// (half-octave bins), each bin counting its neighbours too; its rotation is the bin's centre,
// its scale the median of the matches about the peak. Returns the indices of the matches within
// `maxRotationDeg` and `maxLog2Scale` of it; every index when maxRotationDeg <= 0 or the matches
// are fewer than 8 (maxLog2Scale <= 0: the scale is not checked).
//
// Why joint and not the rotation's peak, then the median scale under it: where the image shows
// a small part of the reference magnified (a zoom of 2.5 and more), only a tenth of the
// reference's corners can match and most matches are chance ones, spread over every rotation
// and scale. The rotation's peak still stands out, but the median scale under it is the chance
// matches', and the true ones, an octave and more from it, were pruned.
std::vector<int> agreeingRotationScale(const std::vector<FeatureMatch>& matches,
                                       double maxRotationDeg, double maxLog2Scale);

}  // namespace facet
