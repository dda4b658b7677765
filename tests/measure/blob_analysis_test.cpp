// Blob analysis: counts, subpixel areas and centroids of discs, ellipse features, polarity,
// thresholds, filters and failures.
#include <gtest/gtest.h>

#include "algorithms/measure/blob_analysis.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet {
namespace {

scene::Scene discs(double background, double grey, double noise = 2.0) {
  scene::SceneSpec spec;
  spec.size = {200, 120};
  spec.background = background;
  spec.blurSigma = 0.9;
  spec.noiseSigma = noise;
  spec.subrows = 64;
  scene::Scene s(spec);
  s.addDisc({30.3, 40.6}, 6.2, grey);
  s.addDisc({80.7, 60.1}, 12.45, grey);
  s.addDisc({150.2, 55.5}, 27.3, grey);
  return s;
}

TEST(BlobAnalysis, CountsDiscsAndMeasuresTheirAreaToSubpixelPrecision) {
  const scene::Scene s = discs(50, 170);
  const BlobResult r = analyseBlobs(s.render());
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.blobs.size(), 3u);
  // Largest first.
  const double radii[] = {27.3, 12.45, 6.2};
  const cv::Point2d centres[] = {{150.2, 55.5}, {80.7, 60.1}, {30.3, 40.6}};
  for (int i = 0; i < 3; ++i) {
    const Blob& b = r.blobs[i];
    const double area = CV_PI * radii[i] * radii[i];
    EXPECT_NEAR(b.area, area, 0.01 * area) << i;
    EXPECT_NEAR(b.centroid.x, centres[i].x, 0.05) << i;
    EXPECT_NEAR(b.centroid.y, centres[i].y, 0.05) << i;
    EXPECT_NEAR(b.majorRadius, radii[i], 0.03 * radii[i]) << i;
    EXPECT_NEAR(b.minorRadius / b.majorRadius, 1.0, 0.03) << i;
    EXPECT_TRUE(b.bbox.contains(cv::Point(centres[i])));
    EXPECT_NEAR(b.bbox.width, 2 * radii[i], 2.0) << i;
    EXPECT_FALSE(b.touchesBorder);
  }
  EXPECT_GT(r.threshold, 50);
  EXPECT_LT(r.threshold, 170);
  // Pixel counts instead: still the right count, and within a few percent.
  BlobParams pixels;
  pixels.greyArea = false;
  const BlobResult counted = analyseBlobs(s.render(), pixels);
  ASSERT_EQ(counted.blobs.size(), 3u);
  EXPECT_EQ(counted.blobs[2].area, counted.blobs[2].pixels);
}

TEST(BlobAnalysis, FindsDarkBlobsWithEveryThresholdMode) {
  const cv::Mat image = discs(200, 60).render();
  BlobParams p;
  p.polarity = BlobPolarity::Dark;
  for (BlobThreshold mode :
       {BlobThreshold::Otsu, BlobThreshold::Fixed, BlobThreshold::RelativeToMedian}) {
    p.mode = mode;
    p.threshold = mode == BlobThreshold::Fixed ? 130.0 : 70.0;
    const BlobResult r = analyseBlobs(image, p);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    EXPECT_EQ(r.blobs.size(), 3u) << static_cast<int>(mode);
    if (mode == BlobThreshold::RelativeToMedian) {
      EXPECT_NEAR(r.threshold, 200 - 70, 3);
    }
  }
}

TEST(BlobAnalysis, FiltersByAreaAndRoundnessAndMeasuresTheEllipse) {
  scene::SceneSpec spec;
  spec.size = {200, 120};
  spec.background = 40;
  spec.blurSigma = 0.9;
  spec.subrows = 64;
  scene::Scene s(spec);
  s.addDisc({40, 60}, 15, 180);
  // An ellipse, semi-axes 30 and 10, its major axis 30 degrees counter-clockwise on screen.
  std::vector<cv::Point2d> ellipse;
  for (int k = 0; k < 360; ++k) {
    const double t = k * CV_PI / 180, a = 30 * CV_PI / 180;
    const double x = 30 * std::cos(t), y = 10 * std::sin(t);
    ellipse.push_back(
        {130.3 + x * std::cos(a) + y * std::sin(a), 60.2 - x * std::sin(a) + y * std::cos(a)});
  }
  s.addPolygon(ellipse, 180);
  const cv::Mat image = s.render();
  BlobParams p;
  const BlobResult both = analyseBlobs(image, p);
  ASSERT_EQ(both.blobs.size(), 2u);
  const Blob& e = both.blobs[0];  // 942 px^2 beats the disc's 707
  EXPECT_NEAR(e.majorRadius, 30, 0.5);
  EXPECT_NEAR(e.minorRadius, 10, 0.3);
  EXPECT_NEAR(e.angle, 30, 0.5);
  p.minRoundness = 0.5;
  const BlobResult round = analyseBlobs(image, p);
  ASSERT_EQ(round.blobs.size(), 1u);
  EXPECT_NEAR(round.blobs[0].centroid.x, 40, 0.05);
  p = {};
  p.maxArea = 800;
  EXPECT_EQ(analyseBlobs(image, p).blobs.size(), 1u);
  p.maxArea = 100;
  EXPECT_EQ(analyseBlobs(image, p).status.cause, MeasureFailure::NoBlob);
}

TEST(BlobAnalysis, WorksInARegionAndFailsWithItsCause) {
  const cv::Mat image = discs(50, 170).render();
  BlobParams p;
  p.roi = {0, 0, 110, 120};  // the two smaller discs
  const BlobResult left = analyseBlobs(image, p);
  ASSERT_TRUE(left.status.ok());
  EXPECT_EQ(left.blobs.size(), 2u);
  EXPECT_NEAR(left.blobs[0].centroid.x, 80.7, 0.05);  // image coordinates
  p.roi = {150, 0, 100, 120};  // sticks out of the image: clipped, the big disc cut
  const BlobResult clipped = analyseBlobs(image, p);
  ASSERT_TRUE(clipped.status.ok());
  EXPECT_TRUE(clipped.partial);
  EXPECT_TRUE(clipped.blobs.at(0).touchesBorder);
  p.roi = {300, 300, 50, 50};
  EXPECT_EQ(analyseBlobs(image, p).status.cause, MeasureFailure::OutsideImage);
  p.roi = {10, 10, 0, 50};
  EXPECT_EQ(analyseBlobs(image, p).status.cause, MeasureFailure::ZeroSize);
  const cv::Mat flat(50, 50, CV_8U, cv::Scalar(100));
  EXPECT_EQ(analyseBlobs(flat).status.cause, MeasureFailure::NoContrast);
}

}  // namespace
}  // namespace facet
