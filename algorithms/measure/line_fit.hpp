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

// The segment the fit's inliers cover: their extent along the line, its direction turned to
// agree with `towards` (p1 to p2 runs that way).
struct LineSegment {
  cv::Point2d p1, p2;
  cv::Point2d direction;  // unit, from p1 to p2
};
LineSegment inlierSegment(const FittedLine& line, const std::vector<cv::Point2d>& points,
                          cv::Point2d towards);

// nullopt when fewer than 3 points or no line has 3 supporters.
std::optional<FittedLine> fitLineRobust(const std::vector<cv::Point2d>& points,
                                        const LineFitParams& params = {});

}  // namespace facet
