#pragma once
// The baselines the measuring tools are compared with, each as a line engineer would build it
// from OpenCV: a classic caliper (profile projected across the rectangle at 1 px spacing,
// Gaussian derivative, parabola through the peak), cv::fitLine on Canny pixels inside the
// rectangle, and connectedComponentsWithStats after an Otsu threshold.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/measuring_path.hpp"

namespace facet::bench {

struct ClassicEdge {
  double position = 0;    // along the axis from the centre, pixels
  double derivative = 0;  // signed peak of the Gaussian derivative
};
// Edges whose derivative peak exceeds `minDerivative` grey levels per pixel, by position.
std::vector<ClassicEdge> classicCaliper(const cv::Mat& image, const MeasuringRect& rect,
                                        double sigma = 1.0, double minDerivative = 5.0);

struct ClassicLine {
  bool ok = false;
  cv::Point2d point, direction;
};
ClassicLine cannyFitLine(const cv::Mat& image, const MeasuringRect& rect);

struct ClassicBlob {
  double area = 0;
  cv::Point2d centroid;
};
std::vector<ClassicBlob> otsuComponents(const cv::Mat& image);

}  // namespace facet::bench
