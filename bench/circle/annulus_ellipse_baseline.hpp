#pragma once
// The circle benchmarks' OpenCV baseline: cv::fitEllipseAMS on the Canny pixels (smoothed and
// thresholded as OpenCV's tutorials do) of a measurement's search annulus, what an OpenCV user
// would write for a round or tilted rim.

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/circle/circle_measure.hpp"

namespace facet::bench {

// The ellipse through the Canny pixels within `p.width` of the circle (p.centre, p.radius);
// nothing with fewer than 6 pixels or a fit that is not finite.
inline std::optional<cv::RotatedRect> annulusEllipseAMS(const cv::Mat& image,
                                                        const CircleMeasureParams& p) {
  cv::Mat smooth, edges;
  cv::GaussianBlur(image, smooth, {5, 5}, 1.5);
  cv::Canny(smooth, edges, 50, 100);
  std::vector<cv::Point2f> pts;
  for (int y = 0; y < edges.rows; ++y)
    for (int x = 0; x < edges.cols; ++x)
      if (edges.at<std::uint8_t>(y, x) &&
          std::abs(std::hypot(x - p.centre.x, y - p.centre.y) - p.radius) <= p.width)
        pts.emplace_back(static_cast<float>(x), static_cast<float>(y));
  if (pts.size() < 6) return std::nullopt;
  const cv::RotatedRect e = cv::fitEllipseAMS(pts);
  if (!std::isfinite(e.center.x) || !std::isfinite(e.center.y) || !std::isfinite(e.size.width) ||
      !std::isfinite(e.size.height))
    return std::nullopt;
  return e;
}

}  // namespace facet::bench
