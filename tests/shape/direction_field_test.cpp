// The search's direction field against its definition: the 3x3 Sobel derivatives of the whole
// image (border replicated), scaled to length 127 and rounded, zero below the minimum contrast;
// computed tile by tile on demand, for 8-bit and float grey images.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/image_gradients.hpp"
#include "tests/shape/bracket_scenes.hpp"

namespace facet {
namespace {

using shape_detail::Direction;

// The field's direction at one pixel from whole-image Sobel derivatives (8 x grey levels per
// pixel), with the field's float arithmetic.
Direction expected(float a, float b, double minContrast) {
  const auto min2 = static_cast<float>(64.0 * minContrast * minContrast);
  const float m2 = a * a + b * b;
  const float inv = m2 >= min2 ? 127.0f / std::sqrt(m2) : 0.0f;
  return {static_cast<schar>(cvRound(a * inv)), static_cast<schar>(cvRound(b * inv))};
}

TEST(DirectionField, TilesOnDemandEqualTheWholeImageSobel) {
  // A size that is no multiple of the tiles, parts reaching the border.
  const cv::Mat scene = testing::bracketScene(
      {203, 157}, {{95, 80, 0.7, 1.0}, {190, 20, 2.0, 1.0}, {10, 130, -1.0, 1.0}});
  const double minContrast = 3.0;  // low: noise counts too
  for (const bool eightBit : {true, false}) {
    const cv::Mat grey = eightBit ? scene : shape_detail::toGreyFloat(scene);
    const int type = eightBit ? CV_16S : CV_32F;
    cv::Mat dx, dy;
    cv::Sobel(grey, dx, type, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(grey, dy, type, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    dx.convertTo(dx, CV_32F);
    dy.convertTo(dy, CV_32F);

    shape_detail::DirectionField field(grey, minContrast);
    const cv::Rect regions[] = {
        {150, 100, 80, 80}, {-10, -10, 40, 20}, {60, 40, 70, 50}, {-5, 90, 30, 80}};
    cv::Mat computed = cv::Mat::zeros(grey.size(), CV_8U);
    for (const cv::Rect& r : regions) {
      field.ensure(r);
      computed(r & cv::Rect(0, 0, grey.cols, grey.rows)).setTo(1);
    }
    int compared = 0, edges = 0;
    for (int y = 0; y < grey.rows; ++y)
      for (int x = 0; x < grey.cols; ++x) {
        if (!computed.at<uchar>(y, x)) continue;
        ++compared;
        const Direction want = expected(dx.at<float>(y, x), dy.at<float>(y, x), minContrast);
        ASSERT_EQ(field.directions().at<Direction>(y, x), want)
            << (eightBit ? "8-bit" : "float") << " at " << x << "," << y;
        edges += want != Direction(0, 0);
      }
    EXPECT_GT(compared, 6000);
    EXPECT_GT(edges, 300);
  }
}

}  // namespace
}  // namespace facet
