#pragma once
// Conics fitted to edge points, and the pole of a line with respect to a conic: the image of a
// circle's centre is the pole of the plane's vanishing line (pole and polar survive any
// projective map), not the centre of the ellipse the circle projects to.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

// Algebraic conic fit (x^T C x = 0, x = (u, v, 1)) on points normalised to zero mean and unit
// spread; nullopt with fewer than 6 points or when the fit is not an ellipse.
std::optional<cv::Matx33d> fitEllipseConic(const std::vector<cv::Point2d>& points);

// Sampson distance of a point to the conic, in the points' unit.
double conicDistance(const cv::Matx33d& conic, cv::Point2d p);

// The pole of `line` (homogeneous l: l . x = 0) with respect to `conic`, as a point.
cv::Point2d conicPole(const cv::Matx33d& conic, const cv::Vec3d& line);

}  // namespace facet
