#pragma once
// A part on a photograph hidden in part behind a flat plate, for the occluded-photograph test and
// benchmark: the plate's straight, anti-aliased border over real texture can stand in for a hidden
// edge of the part.

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"

namespace facet::testing {

enum class HiddenSide { Left, Right, Top, Bottom };  // in the part's own frame
inline constexpr HiddenSide kHiddenSides[] = {HiddenSide::Left, HiddenSide::Right, HiddenSide::Top,
                                              HiddenSide::Bottom};

// `scene` (8-bit grey) with `share` of the part's box hidden from `side` behind a plate of the
// scene's median grey. The box is the template's (`templateSize`, reference point at its centre)
// placed at `pose`, 4 px wider on every side.
cv::Mat hideSide(const cv::Mat& scene, cv::Size templateSize, const Pose2D& pose, HiddenSide side,
                 double share = 1.0 / 3.0);

}  // namespace facet::testing
