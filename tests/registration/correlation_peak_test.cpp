// correlationPeak on surfaces with a known peak.
#include <cmath>

#include <gtest/gtest.h>

#include "algorithms/registration/correlation_peak.hpp"

namespace facet {
namespace {

// 1 - (d' A d) / 2 about `peak`: a quadratic surface, so the 3x3 fit is exact.
cv::Mat quadraticSurface(cv::Point2d peak, const cv::Matx22d& A) {
  cv::Mat s(9, 9, CV_32F);
  for (int y = 0; y < s.rows; ++y)
    for (int x = 0; x < s.cols; ++x) {
      const cv::Vec2d d(x - peak.x, y - peak.y);
      s.at<float>(y, x) = static_cast<float>(1 - 0.5 * (d.t() * A * d)(0));
    }
  return s;
}

TEST(CorrelationPeak, APeakWithTurnedAxesIsFoundWhereTwoParabolasMissIt) {
  // An elongated peak, its long axis turned 35 degrees: sharp across, loose along (an edge).
  const double a = 35 * CV_PI / 180, across = 0.4, along = 0.02;
  const cv::Matx22d R(std::cos(a), -std::sin(a), std::sin(a), std::cos(a));
  const cv::Matx22d A = R * cv::Matx22d(along, 0, 0, across) * R.t();
  const cv::Point2d truth(4.3, 3.8);
  const cv::Mat s = quadraticSurface(truth, A);
  const CorrelationPeak p = correlationPeak(s, {4, 4});
  EXPECT_NEAR(4 + p.offset.x, truth.x, 1e-4);
  EXPECT_NEAR(4 + p.offset.y, truth.y, 1e-4);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(p.curvature.val[k], A.val[k], 1e-4);
  // Parabolas along the row and the column through the best pixel land elsewhere.
  const auto parabola = [](double l, double c, double r) {
    return 0.5 * (l - r) / (l - 2 * c + r);
  };
  const double rowX = 4 + parabola(s.at<float>(4, 3), s.at<float>(4, 4), s.at<float>(4, 5));
  const double colY = 4 + parabola(s.at<float>(3, 4), s.at<float>(4, 4), s.at<float>(5, 4));
  EXPECT_GT(std::hypot(rowX - truth.x, colY - truth.y), 0.1);
}

TEST(CorrelationPeak, ARidgeOrASaddleIsNoPeak) {
  const cv::Mat ridge = quadraticSurface({4, 4}, cv::Matx22d(0.3, 0, 0, 0));
  const CorrelationPeak r = correlationPeak(ridge, {4, 4});
  EXPECT_EQ(r.curvature, cv::Matx22d::zeros());
  EXPECT_EQ(r.offset, cv::Point2d(0, 0));
  const cv::Mat saddle = quadraticSurface({4.2, 4}, cv::Matx22d(0.3, 0, 0, -0.2));
  EXPECT_EQ(correlationPeak(saddle, {4, 4}).curvature, cv::Matx22d::zeros());
}

TEST(CorrelationPeak, TheOffsetStaysWithinHalfAPixel) {
  // A peak beyond the neighbourhood's reach (the best pixel on a slope of a flat peak).
  const cv::Mat s = quadraticSurface({6.5, 4}, cv::Matx22d(0.01, 0, 0, 0.5));
  const CorrelationPeak p = correlationPeak(s, {4, 4});
  EXPECT_DOUBLE_EQ(p.offset.x, 0.5);
  EXPECT_NEAR(p.offset.y, 0.0, 1e-6);
}

}  // namespace
}  // namespace facet
