#include "tests/shape/photo_occlusion.hpp"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace facet::testing {

cv::Mat hideSide(const cv::Mat& scene, cv::Size templateSize, const Pose2D& pose, HiddenSide side,
                 double share) {
  std::vector<uchar> grey(scene.begin<uchar>(), scene.end<uchar>());
  std::nth_element(grey.begin(), grey.begin() + static_cast<std::ptrdiff_t>(grey.size() / 2),
                   grey.end());
  const double plateGrey = grey[grey.size() / 2];
  const double hw = templateSize.width / 2.0 + 4, hh = templateSize.height / 2.0 + 4;
  const double cutX = 2 * hw * share, cutY = 2 * hh * share;
  double x0 = -hw, x1 = hw, y0 = -hh, y1 = hh;
  switch (side) {
    case HiddenSide::Left:
      x1 = -hw + cutX;
      break;
    case HiddenSide::Right:
      x0 = hw - cutX;
      break;
    case HiddenSide::Top:
      y1 = -hh + cutY;
      break;
    case HiddenSide::Bottom:
      y0 = hh - cutY;
      break;
  }
  constexpr int kShift = 4;  // subpixel vertices for the anti-aliased border
  std::vector<cv::Point> plate;
  for (const cv::Point2d& q : {cv::Point2d(x0, y0), {x1, y0}, {x1, y1}, {x0, y1}}) {
    const cv::Point2d v = pose.apply(q);
    plate.emplace_back(cvRound(v.x * (1 << kShift)), cvRound(v.y * (1 << kShift)));
  }
  cv::Mat hidden = scene.clone();
  cv::fillConvexPoly(hidden, plate, cv::Scalar(plateGrey), cv::LINE_AA, kShift);
  return hidden;
}

}  // namespace facet::testing
