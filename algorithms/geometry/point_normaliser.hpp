#pragma once
// Isotropic normalisation of a point set (Hartley): the similarity that moves the centroid to
// the origin and makes the mean distance from it sqrt(2). Fits of homographies and affine maps
// are conditioned by it (pixel coordinates in the hundreds make their equations ill-scaled).

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

[[nodiscard]] inline cv::Matx33d pointNormaliser(const std::vector<cv::Point2d>& pts) {
  cv::Point2d c(0, 0);
  for (const auto& p : pts) c += p;
  c *= 1.0 / static_cast<double>(pts.size());
  double d = 0;
  for (const auto& p : pts) d += std::hypot(p.x - c.x, p.y - c.y);
  d /= static_cast<double>(pts.size());
  const double s = d > 1e-12 ? std::sqrt(2.0) / d : 1.0;
  return {s, 0, -s * c.x, 0, s, -s * c.y, 0, 0, 1};
}

}  // namespace facet
