#pragma once
// A corner-rich synthetic texture for registration tests: random rectangles, triangles and
// ellipses of random grey levels, lightly blurred; and its exact similarity warp.
#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

namespace facet::testing {

inline cv::Mat texturedScene(cv::Size size, std::uint64_t seed, int shapes = 160) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8U, cv::Scalar(110));
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const int grey = rng.uniform(0, 256);
    const int kind = rng.uniform(0, 3);
    const int r = rng.uniform(6, 28);
    if (kind == 0) {
      cv::rectangle(img, cv::Rect(c.x - r, c.y - r / 2, 2 * r, r), cv::Scalar(grey), cv::FILLED);
    } else if (kind == 1) {
      const cv::Point tri[3] = {c, c + cv::Point(rng.uniform(-2 * r, 2 * r), r),
                                c + cv::Point(r, rng.uniform(-2 * r, 2 * r))};
      cv::fillConvexPoly(img, tri, 3, cv::Scalar(grey), cv::LINE_AA);
    } else {
      cv::ellipse(img, c, cv::Size(r, r / 2 + 2), rng.uniform(0, 180), 0, 360, cv::Scalar(grey),
                  cv::FILLED, cv::LINE_AA);
    }
  }
  cv::GaussianBlur(img, img, cv::Size(), 0.8);
  return img;
}

// q = centreOut + s R(a) (p - centreIn), R(a) = [[cos, sin], [-sin, cos]] (Pose2D convention:
// positive a turns counter-clockwise on screen).
inline cv::Matx33d similarity(double angleDeg, double scale, cv::Point2d centreIn,
                              cv::Point2d centreOut) {
  const double a = angleDeg * CV_PI / 180.0, c = std::cos(a) * scale, s = std::sin(a) * scale;
  return {c,  s, centreOut.x - c * centreIn.x - s * centreIn.y,
          -s, c, centreOut.y + s * centreIn.x - c * centreIn.y,
          0,  0, 1};
}

inline cv::Mat warp(const cv::Mat& img, const cv::Matx33d& H, cv::Size size) {
  cv::Mat out;
  cv::warpPerspective(img, out, H, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(110));
  return out;
}

}  // namespace facet::testing
