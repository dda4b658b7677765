#pragma once
// How much of the image the calibration views cover: the share of a grid of cells whose centre
// lies inside the outline of the pattern in at least one view. A lens model is only known where
// views put points; outside, its polynomial extrapolates.

#include <vector>

#include <opencv2/core.hpp>

namespace facet {

// 8-bit mask of `size`, non-zero where some view's pattern outline covers the pixel.
cv::Mat coveredField(cv::Size size, const std::vector<std::vector<cv::Point2d>>& outlines);
// Covered share (0..1) of a mask made by coveredField.
double coveredShare(const cv::Mat& mask);
// The outline of a cols x rows grid of points (its border points, in order).
std::vector<cv::Point2d> gridOutline(const std::vector<cv::Point2d>& points, int cols, int rows);
// The outline of a view's points: the grid's border when `ids` is empty (every point, in plate
// order), else the convex hull of the points seen (a partial view).
std::vector<cv::Point2d> patternOutline(const std::vector<cv::Point2d>& points,
                                        const std::vector<int>& ids, int cols, int rows);

}  // namespace facet
