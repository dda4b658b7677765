#pragma once
// How positions move between a step's reference frame and the live image: homographies (a
// pose is a similarity, kept as 3x3 so that frames chain by multiplication).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"

namespace facet::service {

cv::Matx33d translation(cv::Point2d t);

// The homography of a pose (q = t + s R(a) p) applied to p = r - home: reference pixels -> live.
cv::Matx33d poseMap(const Pose2D& pose, cv::Point2d home);

// Rotation (degrees, counter-clockwise on screen) of a near-similarity map at point p.
double rotationDeg(const cv::Matx33d& H, cv::Point2d p);

// The pixel rectangle `r` (the whole image without one), clipped to an image of `size`.
cv::Rect clampRect(const std::optional<cv::Rect2d>& r, cv::Size size);

// The outer corners of a pixel rectangle (pixel centres are integers: edges lie at +-0.5).
std::vector<cv::Point2d> outerCorners(const cv::Rect& r);

}  // namespace facet::service
