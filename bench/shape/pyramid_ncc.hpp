#pragma once
// The baseline for bench_shape_real: a rotation-searching normalised cross-correlation matcher on
// an image pyramid (cv::matchTemplate, TM_CCOEFF_NORMED with a mask for the turned template),
// as the open-source template matchers built on OpenCV do it: exhaustive on the top level, then
// each candidate refined level by level in a small window and a narrowing angle range.

#include <vector>

#include <opencv2/core.hpp>

namespace facet::bench {

struct NccMatch {
  double x = 0.0, y = 0.0;  // the template centre ((w-1)/2, (h-1)/2) in the image, pixels
  double angleDeg = 0.0;    // counter-clockwise on screen
  double score = 0.0;       // normalised cross-correlation, -1..1
};

// Up to `maxMatches` matches scoring at least `minScore`, best first, any angle.
std::vector<NccMatch> findByPyramidNcc(const cv::Mat& image, const cv::Mat& templ, int maxMatches,
                                       double minScore = 0.6);

}  // namespace facet::bench
