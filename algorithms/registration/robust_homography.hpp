// A homography fitted to all the pairs that support it, each weighted by how well it agrees.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct RobustHomography {
  cv::Matx33d H = cv::Matx33d::eye();  // src -> dst, H(2,2) == 1
  double noise = 0;  // pixels: the transfer errors' scale about H (a 2D Gaussian's sigma)
  // Per pair (pixels^2): the covariance of its transfer error as the fit modelled it, its
  // metric's inverse at the noise scale over its Cauchy weight; what each pair told the fit is
  // the inverse (homography_uncertainty.hpp propagates it).
  std::vector<cv::Matx22d> errorCovariance;
};

// Minimises the Cauchy loss of the transfer errors H src - dst by iteratively re-weighted
// Levenberg-Marquardt from H0. The loss's scale is the pairs' own noise, re-estimated about each
// new H from the median transfer error (that of a 2D Gaussian is sigma * sqrt(2 ln 2)).
// `sharpness`, when given (one positive definite 2x2 per pair, e.g. the curvature of its
// correlation peak), measures each pair's error in its own metric (r' S r, scaled so that the
// median pair's is about its squared length in pixels): a pair located sharply across an edge
// and loosely along it counts across and hardly along. nullopt when the pairs are too few (< 8),
// the sharpness does not fit them, or the fit degenerates.
std::optional<RobustHomography> fitHomographyCauchy(const std::vector<cv::Point2d>& src,
                                                    const std::vector<cv::Point2d>& dst,
                                                    const cv::Matx33d& H0,
                                                    const std::vector<cv::Matx22d>& sharpness = {});

}  // namespace facet
