#include "service/engine/frame_maps.hpp"

#include <cmath>

#include "algorithms/registration/register_images.hpp"

namespace facet::service {

cv::Matx33d translation(cv::Point2d t) {
  return {1, 0, t.x, 0, 1, t.y, 0, 0, 1};
}

cv::Matx33d poseMap(const Pose2D& pose, cv::Point2d home) {
  const double c = std::cos(pose.angle) * pose.scale, s = std::sin(pose.angle) * pose.scale;
  const cv::Matx33d m{c, s, pose.x, -s, c, pose.y, 0, 0, 1};
  return m * translation(-home);
}

double rotationDeg(const cv::Matx33d& H, cv::Point2d p) {
  const cv::Point2d q0 = mapPoint(H, p), q1 = mapPoint(H, p + cv::Point2d(10, 0));
  return degrees(std::atan2(-(q1.y - q0.y), q1.x - q0.x));
}

cv::Rect clampRect(const std::optional<cv::Rect2d>& r, cv::Size size) {
  if (!r) return {0, 0, size.width, size.height};
  const cv::Rect rect(cvRound(r->x), cvRound(r->y), cvRound(r->width), cvRound(r->height));
  return rect & cv::Rect(0, 0, size.width, size.height);
}

std::vector<cv::Point2d> outerCorners(const cv::Rect& r) {
  return {{r.x - 0.5, r.y - 0.5},
          {r.x + r.width - 0.5, r.y - 0.5},
          {r.x + r.width - 0.5, r.y + r.height - 0.5},
          {r.x - 0.5, r.y + r.height - 0.5}};
}

}  // namespace facet::service
