// Image <-> plane mapping against the renderer's exact projection of plane points.
#include "algorithms/calibration/world_mapping.hpp"

#include <gtest/gtest.h>

#include "tests/calibration/calibration_scenes.hpp"

namespace facet {
namespace {

CameraModel modelOf(const scene::LensCamera& c) {
  return {c.matrix(), c.distortion(), c.size};
}

TEST(WorldMapping, MapsPixelsOntoTheTiltedPlaneAndBack) {
  for (double k1 : {-0.3, 0.3}) {
    auto camera = test::testCamera();
    camera.k1 = k1;
    const auto placement = scene::lookAtPlane({40, 30}, 300, 40, 30, 10, camera);
    const WorldMapping mapping(modelOf(camera), {placement.rotation, placement.translationMm, 0});
    for (double x = -20; x <= 100; x += 20)
      for (double y = -10; y <= 70; y += 20) {
        const cv::Point2d pixel = camera.project(placement.toCamera({x, y}));
        if (pixel.x < 0 || pixel.y < 0 || pixel.x > 1279 || pixel.y > 1023) continue;
        const cv::Point2d q = mapping.toPlane(pixel);
        EXPECT_NEAR(q.x, x, 1e-7) << k1;
        EXPECT_NEAR(q.y, y, 1e-7) << k1;
        const cv::Point2d back = mapping.toImage(q);
        EXPECT_NEAR(back.x, pixel.x, 1e-7);
        EXPECT_NEAR(back.y, pixel.y, 1e-7);
      }
  }
}

TEST(WorldMapping, OffsetLiftsThePlaneTowardsTheCamera) {
  const auto camera = test::testCamera();
  const auto placement = scene::lookAtPlane({0, 0}, 300, 20, 0, 0, camera);
  const WorldMapping mapping(modelOf(camera), {placement.rotation, placement.translationMm, 5.0});
  // z points into the plate: a face 5 mm above it is at z = -5.
  const cv::Point2d pixel = camera.project(placement.toCamera({12, 7}, -5.0));
  const cv::Point2d q = mapping.toPlane(pixel);
  EXPECT_NEAR(q.x, 12, 1e-7);
  EXPECT_NEAR(q.y, 7, 1e-7);
  // About 300 mm away at f = 1500 px: 0.2 mm per pixel.
  EXPECT_NEAR(mapping.mmPerPixelAt({640, 512}), 0.2, 0.03);
}

}  // namespace
}  // namespace facet
