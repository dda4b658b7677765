#include "algorithms/edges/subpixel_edges.hpp"

#include <stdexcept>

#include "algorithms/edges/auto_thresholds.hpp"
#include "algorithms/edges/canny.hpp"
#include "algorithms/edges/curvature_bias.hpp"
#include "algorithms/edges/edge_linking.hpp"
#include "algorithms/edges/facet_model.hpp"

namespace facet {

EdgeContours detectSubpixelEdges(const cv::Mat& image, const EdgeParams& params) {
  if (image.empty()) throw std::invalid_argument("detectSubpixelEdges: the image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument(
        "detectSubpixelEdges: expected an 8-bit or 16-bit single-channel image, got " +
        cv::typeToString(image.type()));
  if (!params.mask.empty() && (params.mask.size() != image.size() || params.mask.type() != CV_8UC1))
    throw std::invalid_argument(
        "detectSubpixelEdges: the mask must be CV_8UC1 of the image's size");

  const cv::Rect full(0, 0, image.cols, image.rows);
  const cv::Rect roi = params.roi.empty() ? full : (params.roi & full);
  EdgeContours result;
  if (roi.empty()) return result;

  // The gradient covers the ROI plus one pixel for suppression; edge pixels need the facet's
  // 5x5 window inside the image.
  const cv::Rect area = cv::Rect(roi.x - 1, roi.y - 1, roi.width + 2, roi.height + 2) & full;
  const EdgeGradient gradient = computeEdgeGradient(image, area);
  const cv::Rect usable = cv::Rect(2, 2, image.cols - 4, image.rows - 4) & roi;
  const cv::Rect candidates = usable - area.tl();
  const cv::Mat mask = params.mask.empty() ? cv::Mat() : params.mask(area);

  if (params.low && params.high) {
    result.lowThreshold = *params.low;
    result.highThreshold = *params.high;
  } else {
    cv::Mat region = cv::Mat::zeros(area.size(), CV_8U);
    region(candidates).setTo(255);
    if (!mask.empty()) region &= mask;
    const CannyThresholds t = autoCannyThresholds(gradient.magnitude, region);
    result.lowThreshold = t.low;
    result.highThreshold = t.high;
  }
  const cv::Mat edges =
      cannyFromGradient(gradient, result.lowThreshold, result.highThreshold, mask, candidates);

  std::vector<cv::Point> pixels;
  for (int y = 0; y < edges.rows; ++y) {
    const auto* e = edges.ptr<uchar>(y);
    for (int x = 0; x < edges.cols; ++x) {
      if (!e[x]) continue;
      const cv::Point p = cv::Point(x, y) + area.tl();
      if (auto point = facetEdgePoint(image, p)) {
        result.points.push_back(*point);
        pixels.push_back(p);
      }
    }
  }
  if (params.linkContours || params.correctCurvatureBias) {
    result.contours = linkEdgePoints(result.points, pixels);
    if (params.correctCurvatureBias) correctCurvatureBias(result.points, result.contours);
    if (!params.linkContours) result.contours.clear();
  }
  return result;
}

}  // namespace facet
