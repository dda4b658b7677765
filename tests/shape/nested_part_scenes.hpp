#pragma once
// Scenes of a small part whose contours lie 2-3 px apart, as a packaged LED's: a housing, a frame
// set unevenly inside it, a window in the frame, a lens ring off the centre and a bright spot.
// Its housing makes it nearly symmetric under a half turn on coarse pyramid levels.

#include <cstdint>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"

namespace facet::testing {

// An image of `size` with the part at `pose` (part coordinates centred on the housing), through a
// lens (blur 0.9, noise 2). `sharpened`: then sharpened as cameras do by default (an unsharp
// mask: the image plus its difference from a blurred copy), which gives every edge an overshoot
// that no blurred step has. The template is the part at ((w-1)/2, (h-1)/2) in 140 x 100.
// `lensShift`: the lens moved by that much in part coordinates and the frame by as much the other
// way, the housing in place, as they sit in some parts of a batch: a part whose contours differ
// from the template's by a few pixels, which no rigid pose matches.
cv::Mat nestedPartScene(cv::Size size, const Pose2D& pose, std::uint64_t seed, bool sharpened,
                        cv::Point2d lensShift = {0.0, 0.0});

}  // namespace facet::testing
