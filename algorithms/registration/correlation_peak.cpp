#include "algorithms/registration/correlation_peak.hpp"

#include <algorithm>

namespace facet {

CorrelationPeak correlationPeak(const cv::Mat& surface, cv::Point best) {
  CV_Assert(surface.type() == CV_32F && best.x > 0 && best.y > 0 && best.x < surface.cols - 1 &&
            best.y < surface.rows - 1);
  const auto at = [&](int dx, int dy) {
    return static_cast<double>(surface.at<float>(best.y + dy, best.x + dx));
  };
  const double c = at(0, 0);
  const double gx = (at(1, 0) - at(-1, 0)) / 2, gy = (at(0, 1) - at(0, -1)) / 2;
  const double hxx = at(1, 0) - 2 * c + at(-1, 0), hyy = at(0, 1) - 2 * c + at(0, -1);
  const double hxy = (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1)) / 4;
  CorrelationPeak peak;
  const double det = hxx * hyy - hxy * hxy;
  if (!(hxx < 0 && hyy < 0 && det > 0)) return peak;
  peak.offset = {std::clamp((-hyy * gx + hxy * gy) / det, -0.5, 0.5),
                 std::clamp((hxy * gx - hxx * gy) / det, -0.5, 0.5)};
  peak.curvature = {-hxx, -hxy, -hxy, -hyy};
  return peak;
}

}  // namespace facet
