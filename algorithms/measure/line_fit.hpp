#pragma once
// Robust straight-line fit to edge points: RANSAC for the consensus set, then orthogonal least
// squares reweighted with Tukey's biweight (scale from the residuals' median absolute deviation),
// so that burrs, dust and a neighbouring edge neither tilt nor shift the line.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct LineFitParams {
  double ransacThreshold = 1.0;  // pixels: a point within this of a 2-point line supports it
  double minScale = 0.02;        // pixels: floor of the robust residual scale
  int iterations = 6;            // reweighting rounds
};

struct FittedLine {
  cv::Point2d point;         // a point on the line (the inliers' weighted centroid)
  cv::Point2d direction;     // unit direction
  std::vector<int> inliers;  // indices of points with non-zero final weight
  double rms = 0;            // RMS orthogonal residual of the inliers, pixels
  double straightness = 0;   // largest |orthogonal residual| among the inliers, pixels
};

// nullopt when fewer than 3 points or no line has 3 supporters.
std::optional<FittedLine> fitLineRobust(const std::vector<cv::Point2d>& points,
                                        const LineFitParams& params = {});

}  // namespace facet
