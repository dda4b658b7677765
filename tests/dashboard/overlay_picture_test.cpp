// The overlay picture an engineer looks at: labels inside the picture and clear of each other,
// the banner naming the failing check with its value.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "service/daemon/part_banner.hpp"
#include "service/engine/label_placement.hpp"
#include "service/engine/overlay.hpp"

namespace facet::service {
namespace {

void expectInsideAndApart(const std::vector<cv::Rect>& boxes, cv::Size picture, int top) {
  const cv::Rect area(0, top, picture.width, picture.height - top);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_EQ(boxes[i] & area, boxes[i]) << "label " << i << " " << boxes[i] << " leaves " << area;
    for (std::size_t k = 0; k < i; ++k)
      EXPECT_EQ((boxes[i] & boxes[k]).area(), 0)
          << "labels " << k << " and " << i << " overlap: " << boxes[k] << " " << boxes[i];
  }
}

TEST(LabelPlacement, LabelsNearTheRightEdgeAndCloseTogetherStayInsideAndApart) {
  // Five features a few pixels apart near the right edge, each with a 200 px label: drawn at
  // their anchors they ran off the picture and covered each other.
  const cv::Size picture(640, 480);
  std::vector<LabelRequest> requests;
  for (int i = 0; i < 5; ++i) requests.push_back({{600.0 + i, 40.0 + 6 * i}, {200, 16}});
  const auto boxes = placeLabels(picture, 22, requests);
  ASSERT_EQ(boxes.size(), requests.size());
  expectInsideAndApart(boxes, picture, 22);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_EQ(boxes[i].size(), requests[i].size);
    // Still near its feature: within a few label heights.
    const cv::Point2d centre(boxes[i].x + boxes[i].width / 2.0, boxes[i].y + boxes[i].height / 2.0);
    EXPECT_LT(cv::norm(centre - requests[i].anchor), 200.0) << i;
  }
}

TEST(LabelPlacement, ALabelWithRoomSitsBesideItsAnchor) {
  const auto boxes = placeLabels({640, 480}, 22, {{{100, 200}, {80, 14}}});
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_EQ(boxes[0], cv::Rect(100, 186, 80, 14));
}

TEST(OverlayPicture, LongLabelsAreWrappedAndDrawnInsideThePicture) {
  // A label as the inspection writes it for a circle step, at a bore near the right edge.
  cv::Mat image(240, 320, CV_8U, cv::Scalar(128));
  Overlay overlay;
  overlay.circle({300, 120}, 10, false);
  overlay.label({308, 112},
                "big_bore diameter=1.203 x=0.012 y=-0.004 position=0.013 roundness=0.004", false);
  overlay.label({300, 130}, "small_bore diameter=0.501 x=0.500 y=0.001 position=0.500", false);
  const cv::Mat picture = drawOverlay(image, overlay, "part 3  fail", false);
  // The label backing is a colour of its own: find its pixels, and the boxes they form.
  cv::Mat backing;
  cv::inRange(picture, cv::Scalar(70, 30, 20), cv::Scalar(70, 30, 20), backing);
  ASSERT_GT(cv::countNonZero(backing), 0);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(backing, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  ASSERT_EQ(contours.size(), 2u) << "two labels, apart";
  for (const auto& c : contours) {
    const cv::Rect box = cv::boundingRect(c);
    EXPECT_GT(box.x, 0) << box;
    EXPECT_LT(box.x + box.width, picture.cols) << box << ": cut off at the right edge";
    EXPECT_GT(box.y, 22) << box << ": under the banner";
    EXPECT_GT(box.height, 20) << box << ": a long label wraps onto more lines";
  }
}

TEST(PartBanner, NamesTheFailingCheckWithItsValueAndBand) {
  PartResult part;
  part.verdict = Verdict::Fail;
  part.measurements.push_back({.name = "label_angle.angle",
                               .value = 7.3126,
                               .unit = "deg",
                               .nominal = 0.0,
                               .tolMinus = 5.0,
                               .tolPlus = 5.0,
                               .checked = true,
                               .pass = false});
  part.measurements.push_back({.name = "big_bore.diameter",
                               .value = std::nan(""),
                               .unit = "mm",
                               .checked = true,
                               .pass = false});
  part.failedChecks = {"label_angle.angle", "big_bore.diameter"};
  EXPECT_EQ(partBanner(part, "part 20"),
            "part 20  fail  label_angle.angle = 7.313 deg, band -5..5  +1 more");
  part.failedChecks = {"big_bore.diameter"};
  EXPECT_EQ(partBanner(part, "BR_003"), "BR_003  fail  big_bore.diameter not measured");
  part.verdict = Verdict::Error;
  part.error = "alignment failed: too_few_inliers";
  EXPECT_EQ(partBanner(part, "part 4"), "part 4  error  alignment failed: too_few_inliers");
}

}  // namespace
}  // namespace facet::service
