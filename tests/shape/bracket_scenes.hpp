#pragma once
// Scenes of the bracket part for the shape tests: the template, and images with the part at
// known poses (blur 0.8, noise 2, contrast 120 unless said otherwise).

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "tests/support/scene/parts.hpp"

namespace facet::testing {

inline constexpr double kPartGrey = 170.0;
inline constexpr double kBackground = 50.0;

scene::SceneSpec bracketSpec(cv::Size size, std::uint64_t seed);

// The bracket's template (160 x 130), light part on dark background.
cv::Mat bracketTemplate(int depth = CV_8U);

// An image of `size` with the bracket at each pose, painted in order (later ones on top).
cv::Mat bracketScene(cv::Size size, const std::vector<Pose2D>& poses, std::uint64_t seed = 7,
                     double partGrey = kPartGrey, double background = kBackground,
                     int depth = CV_8U);

}  // namespace facet::testing
