#pragma once
// Straight-edge test images under the two image formations the tools must both measure right:
// blurred on the pixel grid after integration (tests/support/scene) and blurred by a lens before
// the pixel integrates (computed here directly: each pixel the mean of the analytic blurred step
// over 16 x 16 points of its area).

#include <cmath>

#include <opencv2/core.hpp>

#include "tests/support/scene/scene.hpp"

namespace facet::test {

// Grey `dark` where (p - through) . normal < 0, `light` beyond, as an 8-bit image.
inline cv::Mat lensEdgeImage(cv::Size size, cv::Point2d through, cv::Point2d normal, double dark,
                             double light, double blur) {
  cv::Mat image(size, CV_8U);
  const int n = 16;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      double sum = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const cv::Point2d p(x - 0.5 + (i + 0.5) / n, y - 0.5 + (j + 0.5) / n);
          const double u = (p - through).dot(normal);
          sum += 0.5 * std::erfc(-u / (blur * std::sqrt(2.0)));
        }
      image.at<uchar>(y, x) = cv::saturate_cast<uchar>(dark + (light - dark) * sum / (n * n));
    }
  return image;
}

inline cv::Mat gridEdgeImage(cv::Size size, cv::Point2d through, cv::Point2d normal, double dark,
                             double light, double blur, double noise = 0, std::uint64_t seed = 1) {
  scene::SceneSpec spec;
  spec.size = size;
  spec.background = dark;
  spec.blurSigma = blur;
  spec.noiseSigma = noise;
  spec.subrows = 64;
  spec.seed = seed;
  scene::Scene s(spec);
  const cv::Point2d t(-normal.y, normal.x);
  const double far = 1000;
  s.addPolygon({through + far * t, through + far * t + far * normal,
                through - far * t + far * normal, through - far * t},
               light);
  return s.render();
}

// The axis direction of the design's convention for `deg` degrees.
inline cv::Point2d axisOf(double deg) {
  return {std::cos(deg * CV_PI / 180.0), -std::sin(deg * CV_PI / 180.0)};
}

}  // namespace facet::test
