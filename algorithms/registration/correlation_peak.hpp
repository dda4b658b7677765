// The subpixel peak of a correlation surface, and how sharply it locates the match.
#pragma once

#include <opencv2/core.hpp>

namespace facet {

struct CorrelationPeak {
  cv::Point2d offset;  // subpixel offset from the best pixel, each coordinate within +-0.5
  // Minus the surface's Hessian at the peak (per pixel^2): how sharply the match is located in
  // each direction (across an edge sharply, along it hardly). Zero where the surface is no peak
  // there (a ridge or a saddle); the offset is then zero too.
  cv::Matx22d curvature = cv::Matx22d::zeros();
};

// The quadratic through the 3x3 neighbourhood of `best` (a float surface, best not on its
// border): gradient and Hessian by central differences, the offset where the gradient vanishes.
// Why not a parabola along x and one along y: for a peak whose axes are turned (a diagonal
// edge, a view turned and magnified) the best of a row is not the best of the surface, and
// the two parabolas miss the peak by up to a few tenths of a pixel.
CorrelationPeak correlationPeak(const cv::Mat& surface, cv::Point best);

}  // namespace facet
