// A homography fitted to all the pairs that support it, each weighted by how well it agrees.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct RobustHomography {
  cv::Matx33d H = cv::Matx33d::eye();  // src -> dst, H(2,2) == 1
  double noise = 0;                    // pixels: the pairs' scale about H (see below)
};

// Minimises the Cauchy loss of the transfer errors |H src - dst| by iteratively re-weighted
// Levenberg-Marquardt from H0. The loss's scale is the pairs' own noise, re-estimated about each
// new H from the median transfer error (that of a 2D Gaussian is sigma * sqrt(2 ln 2)).
// nullopt when the pairs are too few (< 8) or the fit degenerates.
std::optional<RobustHomography> fitHomographyCauchy(const std::vector<cv::Point2d>& src,
                                                    const std::vector<cv::Point2d>& dst,
                                                    const cv::Matx33d& H0);

}  // namespace facet
