// A located part's offset in the measuring plane (pose_offset.hpp), against a part placed in a
// tilted plane and carried into the image through the camera.
#include "service/engine/steps/pose_offset.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace facet::service {
namespace {

// A camera 200 mm above a plane tilted 30 degrees about its x axis: the scale in the image
// changes from row to row, and a pixel step in x is not a pixel step in y.
WorldMapping tiltedPlane() {
  const double t = 30 * CV_PI / 180;
  PlanePose plane;
  plane.rotation = cv::Matx33d(1, 0, 0, 0, std::cos(t), -std::sin(t), 0, std::sin(t), std::cos(t));
  plane.translationMm = {-20, -15, 200};
  CameraModel camera;
  camera.cameraMatrix = cv::Matx33d(2400, 0, 319.5, 0, 2400, 239.5, 0, 0, 1);
  camera.distortion = (cv::Mat_<double>(1, 5) << -0.2, 0.05, 0, 0, 0);
  camera.imageSize = {640, 480};
  return {camera, plane};
}

TEST(PoseOffset, WithoutAPlaneOffsetsArePixelsOfTheImage) {
  StepResult r;
  ASSERT_TRUE(setPoseOffset(r, std::nullopt, {100, 80}, {103.5, 78}, 4.0));
  EXPECT_FALSE(r.lengthsInMm);
  EXPECT_DOUBLE_EQ(r.values["x"], 3.5);
  EXPECT_DOUBLE_EQ(r.values["y"], -2.0);
  EXPECT_DOUBLE_EQ(r.values["angle"], 4.0);
}

TEST(PoseOffset, InATiltedPlaneOffsetAndTurnAreThePlanes) {
  const WorldMapping plane = tiltedPlane();
  // The part sits 3 mm along the plane's x and -2 mm along its y from its nominal place, turned
  // 7 degrees in the plane (counter-clockwise as on screen, the plane's y running down).
  const cv::Point2d nominal(300, 200);
  const cv::Point2d nominalMm = plane.toPlane(nominal);
  const cv::Point2d foundMm = nominalMm + cv::Point2d(3, -2);
  cv::Point2d dir = plane.toPlane(nominal + cv::Point2d(1, 0)) - nominalMm;
  dir /= cv::norm(dir);
  const double a = 7 * CV_PI / 180;
  const cv::Point2d turned(std::cos(a) * dir.x + std::sin(a) * dir.y,
                           -std::sin(a) * dir.x + std::cos(a) * dir.y);
  const cv::Point2d found = plane.toImage(foundMm);
  const cv::Point2d g = plane.toImage(foundMm + 1e-3 * turned) - found;
  const double imageAngle = std::atan2(-g.y, g.x) * 180 / CV_PI;

  StepResult r;
  ASSERT_TRUE(setPoseOffset(r, plane, nominal, found, imageAngle));
  EXPECT_TRUE(r.lengthsInMm);
  EXPECT_NEAR(r.values["x"], 3.0, 1e-9);
  EXPECT_NEAR(r.values["y"], -2.0, 1e-9);
  EXPECT_NEAR(r.values["angle"], 7.0, 1e-3);
  // In the image the turn reads otherwise, and pixels times the scale at the nominal place miss
  // the offset by more than a line's tolerance.
  EXPECT_GT(std::abs(imageAngle - 7.0), 0.3);
  const double scale = plane.mmPerPixelAt(nominal);
  EXPECT_GT(std::abs((found.y - nominal.y) * scale - -2.0), 0.05);
}

}  // namespace
}  // namespace facet::service
