#include "algorithms/circle/disc_locator.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

// An antialiased disc of `radius` (1 inside, 0 outside, linear over one pixel at the rim) in a
// template with a ring of background around it, so the correlation sees the contrast.
cv::Mat discTemplate(double radius) {
  const int half = static_cast<int>(std::ceil(radius * 1.5)) + 2;
  cv::Mat t(2 * half + 1, 2 * half + 1, CV_32F);
  for (int y = 0; y < t.rows; ++y)
    for (int x = 0; x < t.cols; ++x) {
      const double d = std::hypot(x - half, y - half);
      t.at<float>(y, x) = static_cast<float>(std::clamp(radius + 0.5 - d, 0.0, 1.0));
    }
  return t;
}

}  // namespace

std::optional<DiscLocation> locateDisc(const cv::Mat& image, const DiscSearch& search) {
  if (image.empty() || image.channels() != 1 || search.radius <= 1 || search.searchRadius < 0)
    return std::nullopt;
  const cv::Mat templ = discTemplate(search.radius);
  const int half = templ.rows / 2;
  const int reach = static_cast<int>(std::ceil(search.searchRadius)) + half;
  const cv::Rect window =
      cv::Rect(cvRound(search.expected.x) - reach, cvRound(search.expected.y) - reach,
               2 * reach + 1, 2 * reach + 1) &
      cv::Rect(0, 0, image.cols, image.rows);
  if (window.width < templ.cols || window.height < templ.rows) return std::nullopt;
  cv::Mat patch;
  image(window).convertTo(patch, CV_32F);
  cv::Mat score;
  cv::matchTemplate(patch, templ, score, cv::TM_CCOEFF_NORMED);
  // The template is a light disc: a dark disc correlates negatively.
  if (search.polarity == CirclePolarity::DarkToLight) score = -score;
  if (search.polarity == CirclePolarity::Any) score = cv::abs(score);
  std::optional<DiscLocation> best;
  for (int y = 0; y < score.rows; ++y)
    for (int x = 0; x < score.cols; ++x) {
      const cv::Point2d centre(window.x + x + half, window.y + y + half);
      if (cv::norm(centre - search.expected) > search.searchRadius) continue;
      const double s = score.at<float>(y, x);
      if (s >= search.minScore && (!best || s > best->score)) best = DiscLocation{centre, s};
    }
  return best;
}

}  // namespace facet
