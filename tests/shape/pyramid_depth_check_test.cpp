// The automatic pyramid's depth: refused where the part's pattern repeats within the top level's
// reach (findSearchPeriods), and tested on copies of the template
// (algorithms/shape/pyramid_depth_check.hpp); checked on a scene neither saw: a second camera
// image of the photographed part, turned.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/pyramid_depth_check.hpp"
#include "tests/shape/test_photos.hpp"

namespace facet {
namespace {

using testing::testPhoto;

// A patch of a calibration chessboard (tests/data/photos/right04.png) as a camera of half the
// photograph's resolution sees it: each camera pixel the mean of 2x2 (its aperture). On the top
// level of the pyramid the template's edges keep (4 levels: 1/8, a square about 1.6 px there)
// the squares alias.
const cv::Rect kPatch(40, 74, 61, 100);

cv::Mat cameraImage(const cv::Mat& fine) {
  cv::Mat image;
  cv::resize(fine, image, cv::Size(fine.cols / 2, fine.rows / 2), 0, 0, cv::INTER_AREA);
  return image;
}

// The patch's training parameters: `levels` pyramid levels, 0 = automatic.
ShapeModelParams patchParams(int levels) {
  ShapeModelParams params;
  params.roi = kPatch;
  params.numLevels = levels;
  return params;
}

struct Shot {
  cv::Mat image;
  Pose2D truth;  // of the patch's centre
};

// The camera's second shot of the chessboard turned about the photograph's centre by `degrees`
// at `scale` (cubic at the photograph's resolution), with noise of sigma 1.5.
Shot turnedShot(const cv::Mat& fine, double degrees, double scale) {
  const cv::Mat turn = cv::getRotationMatrix2D(
      cv::Point2f((fine.cols - 1) / 2.0F, (fine.rows - 1) / 2.0F), degrees, scale);
  cv::Mat turned;
  cv::warpAffine(fine, turned, turn, fine.size(), cv::INTER_CUBIC, cv::BORDER_CONSTANT,
                 cv::mean(fine));
  cv::Mat noise(turned.rows / 2, turned.cols / 2, CV_32F), sum;
  cv::setRNGSeed(1);
  cv::randn(noise, 0.0, 1.5);
  cameraImage(turned).convertTo(sum, CV_32F);
  sum += noise;
  Shot shot;
  sum.convertTo(shot.image, CV_8U);
  // The patch's centre in camera pixels -> photograph pixels -> turned -> camera pixels.
  const cv::Matx23d m = turn;
  const cv::Point2d c(2.0 * (kPatch.x + (kPatch.width - 1) / 2.0) + 0.5,
                      2.0 * (kPatch.y + (kPatch.height - 1) / 2.0) + 0.5);
  shot.truth = {(m(0, 0) * c.x + m(0, 1) * c.y + m(0, 2) - 0.5) / 2.0,
                (m(1, 0) * c.x + m(1, 1) * c.y + m(1, 2) - 0.5) / 2.0,
                degrees * std::numbers::pi / 180.0, scale};
  return shot;
}

// The pyramid its edges allow (4 levels) sees the chessboard's period within its top level's reach
// and loses copies of the patch that 3 levels find; the automatic model refuses 4 levels for the
// period, takes 3 and says what it tried.
TEST(PyramidDepthCheck, TheAliasedTopLevelOfAChessboardIsGivenUp) {
  const cv::Mat fine = testPhoto("right04.png");
  ASSERT_FALSE(fine.empty());
  const cv::Mat photo = cameraImage(fine);
  EXPECT_GT(copiesLostBySearch(photo(kPatch), createShapeModel(photo, patchParams(4))), 0);
  EXPECT_EQ(copiesLostBySearch(photo(kPatch), createShapeModel(photo, patchParams(3))), 0);

  const ShapeModel automatic = createShapeModel(photo, patchParams(0));
  EXPECT_EQ(automatic.numLevels(), 3);
  ASSERT_EQ(automatic.pyramidTrials.size(), 2u);
  EXPECT_EQ(automatic.pyramidTrials[0].levels, 4);
  EXPECT_TRUE(automatic.pyramidTrials[0].period.has_value());
  EXPECT_EQ(automatic.pyramidTrials[1].levels, 3);
  EXPECT_FALSE(automatic.pyramidTrials[1].period.has_value());
  EXPECT_EQ(automatic.pyramidTrials[1].copiesLost, 0);
}

// An apple (tests/data/photos/apple.png) whose upper levels see an outline that is nearly round:
// they leave the angle and the place off by more than the levels below look around, and copies of
// the template are lost with 3 and 2 levels. No period refuses them; the copies' test gives them
// up, and one level finds every copy.
TEST(PyramidDepthCheck, ADepthThatLosesCopiesIsGivenUp) {
  const cv::Mat photo = testPhoto("apple.png");
  ASSERT_FALSE(photo.empty());
  ShapeModelParams params;
  params.roi = cv::Rect(251, 133, 149, 110);
  const ShapeModel automatic = createShapeModel(photo, params);
  ASSERT_EQ(automatic.pyramidTrials.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const PyramidTrial& trial = automatic.pyramidTrials[static_cast<std::size_t>(k)];
    EXPECT_EQ(trial.levels, 3 - k);
    EXPECT_FALSE(trial.period.has_value());
    if (k < 2) {
      EXPECT_GT(trial.copiesLost, 0) << trial.levels << " levels";
    }
  }
  EXPECT_EQ(automatic.pyramidTrials[2].copiesLost, 0);
  EXPECT_EQ(automatic.numLevels(), 1);
}

// The camera's second shot, turned by -165.71 degrees at scale 1.01: with 4 levels the search
// returned a neighbouring pair of squares (0.954, 29 px off) while the part scores 0.999; the
// automatic model finds the part.
TEST(PyramidDepthCheck, TheAutomaticModelFindsTheChessboardPatchInASecondShot) {
  const cv::Mat fine = testPhoto("right04.png");
  ASSERT_FALSE(fine.empty());
  const cv::Mat photo = cameraImage(fine);
  const Shot shot = turnedShot(fine, -165.71, 1.01);
  const auto found = findShapeModel(shot.image, createShapeModel(photo, patchParams(0)));
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(std::hypot(found[0].x - shot.truth.x, found[0].y - shot.truth.y), 0.2);
  EXPECT_NEAR(found[0].angle, shot.truth.angle, 0.2 * std::numbers::pi / 180.0);
  EXPECT_GT(found[0].score, 0.99);

  // The pyramid the edges allow, untested.
  const auto deep = findShapeModel(shot.image, createShapeModel(photo, patchParams(4)));
  ASSERT_FALSE(deep.empty());
  EXPECT_GT(std::hypot(deep[0].x - shot.truth.x, deep[0].y - shot.truth.y), 10.0)
      << "the 4-level pyramid finds the part: the test no longer shows what the check is for";
}

// A part without a periodic pattern keeps the pyramid its edges allow: the test finds every copy.
TEST(PyramidDepthCheck, APartThatFindsItsCopiesKeepsItsLevels) {
  const cv::Mat photo = testPhoto("board_qfp44_template.png");
  ASSERT_FALSE(photo.empty());
  const ShapeModel automatic = createShapeModel(photo);
  ASSERT_EQ(automatic.pyramidTrials.size(), 1u);
  EXPECT_EQ(automatic.pyramidTrials[0].levels, automatic.numLevels());
  EXPECT_EQ(automatic.pyramidTrials[0].copiesLost, 0);
  EXPECT_GT(automatic.numLevels(), 1);
}

// Levels given by the user are kept and not tested.
TEST(PyramidDepthCheck, GivenLevelsAreNotTested) {
  const cv::Mat fine = testPhoto("right04.png");
  ASSERT_FALSE(fine.empty());
  const ShapeModel model = createShapeModel(cameraImage(fine), patchParams(4));
  EXPECT_EQ(model.numLevels(), 4);
  EXPECT_TRUE(model.pyramidTrials.empty());
}

}  // namespace
}  // namespace facet
