#include <gtest/gtest.h>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/geometry/ransac.hpp"

namespace facet {
namespace {

TEST(Pose2D, PositiveAngleTurnsCounterClockwiseOnScreen) {
  // With y down, a point to the right of the reference (1, 0) turned +90 degrees on screen
  // (counter-clockwise) ends up above it, at y = -1.
  const Pose2D pose{0, 0, radians(90), 1};
  const cv::Point2d q = pose.apply({1, 0});
  EXPECT_NEAR(q.x, 0, 1e-12);
  EXPECT_NEAR(q.y, -1, 1e-12);
}

TEST(Pose2D, InverseAndComposeRoundTrip) {
  const Pose2D a{10.5, -3.25, radians(33), 1.2};
  const Pose2D b{-4, 7, radians(-71), 0.9};
  const cv::Point2d p{3.3, -8.1};
  const cv::Point2d back = a.inverse().apply(a.apply(p));
  EXPECT_NEAR(back.x, p.x, 1e-12);
  EXPECT_NEAR(back.y, p.y, 1e-12);
  const cv::Point2d viaCompose = a.compose(b).apply(p);
  const cv::Point2d stepwise = a.apply(b.apply(p));
  EXPECT_NEAR(viaCompose.x, stepwise.x, 1e-12);
  EXPECT_NEAR(viaCompose.y, stepwise.y, 1e-12);
}

TEST(Pose2D, WrapAngle) {
  EXPECT_NEAR(wrapAngle(radians(190)), radians(-170), 1e-12);
  EXPECT_NEAR(wrapAngle(radians(-180)), radians(180), 1e-12);
}

TEST(Ransac, FindsLineDespiteHalfOutliers) {
  std::vector<cv::Point2d> pts;
  for (int i = 0; i < 50; ++i) pts.push_back({double(i), 2.0 * i + 1});
  for (int i = 0; i < 50; ++i) pts.push_back({double(i), double((i * 37) % 101)});
  struct Line {
    double a, b;
  };
  auto res = ransac<Line>(
      pts.size(), 2,
      [&](const std::vector<std::size_t>& s) -> std::optional<Line> {
        const auto p = pts[s[0]], q = pts[s[1]];
        if (p.x == q.x) return std::nullopt;
        const double a = (q.y - p.y) / (q.x - p.x);
        return Line{a, p.y - a * p.x};
      },
      [&](const Line& l, std::size_t i) { return std::abs(l.a * pts[i].x + l.b - pts[i].y); },
      {.inlierThreshold = 0.1});
  ASSERT_TRUE(res);
  EXPECT_NEAR(res->model.a, 2.0, 1e-9);
  EXPECT_GE(res->inliers.size(), 50u);
  EXPECT_LE(res->inliers.size(), 53u);
}

}  // namespace
}  // namespace facet
