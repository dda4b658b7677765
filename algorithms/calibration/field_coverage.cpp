#include "algorithms/calibration/field_coverage.hpp"

#include <opencv2/imgproc.hpp>

namespace facet {

cv::Mat coveredField(cv::Size size, const std::vector<std::vector<cv::Point2d>>& outlines) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8U);
  for (const auto& outline : outlines) {
    std::vector<cv::Point> poly;
    poly.reserve(outline.size());
    for (const auto& p : outline) poly.emplace_back(cvRound(p.x), cvRound(p.y));
    if (poly.size() >= 3) cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{poly}, 255);
  }
  return mask;
}

double coveredShare(const cv::Mat& mask) {
  return mask.empty() ? 0.0 : cv::countNonZero(mask) / static_cast<double>(mask.total());
}

std::vector<cv::Point2d> gridOutline(const std::vector<cv::Point2d>& p, int cols, int rows) {
  std::vector<cv::Point2d> out;
  auto at = [&](int c, int r) { return p[static_cast<std::size_t>(r * cols + c)]; };
  for (int c = 0; c < cols; ++c) out.push_back(at(c, 0));
  for (int r = 1; r < rows; ++r) out.push_back(at(cols - 1, r));
  for (int c = cols - 2; c >= 0; --c) out.push_back(at(c, rows - 1));
  for (int r = rows - 2; r > 0; --r) out.push_back(at(0, r));
  return out;
}

std::vector<cv::Point2d> patternOutline(const std::vector<cv::Point2d>& points,
                                        const std::vector<int>& ids, int cols, int rows) {
  if (ids.empty()) return gridOutline(points, cols, rows);
  std::vector<cv::Point2f> in(points.begin(), points.end()), hull;
  if (in.size() >= 3) cv::convexHull(in, hull);
  return {hull.begin(), hull.end()};
}

}  // namespace facet
