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
// automatic model finds the part. So does the 4-level one now that the search tracks each
// top-level candidate's neighbours one period away (ShapeModel::trackedPeriods), and without them
// it still returns the neighbour.
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
  ShapeModel deepModel = createShapeModel(photo, patchParams(4));
  ASSERT_FALSE(deepModel.trackedPeriods.empty());
  const auto tracked = findShapeModel(shot.image, deepModel);
  ASSERT_FALSE(tracked.empty());
  EXPECT_LT(std::hypot(tracked[0].x - shot.truth.x, tracked[0].y - shot.truth.y), 0.2);
  deepModel.trackedPeriods.clear();
  const auto deep = findShapeModel(shot.image, deepModel);
  ASSERT_FALSE(deep.empty());
  EXPECT_GT(std::hypot(deep[0].x - shot.truth.x, deep[0].y - shot.truth.y), 10.0)
      << "the 4-level pyramid finds the part: the test no longer shows what the check is for";
}

// Lines of small print (tests/data/photos/text_lines_*.png): on the third level, 1/4, the letters
// blur into rows, which score the part on turned copies of the template at 0.57-0.75 of what
// level 0 scores it, where the search assumes 0.7 (it keeps top-level candidates from 0.7 x the
// minimum score). The search with 3 levels finds every copy, each scoring 0.97 at level 0; in a
// second shot turned -167.4 degrees the part scores 0.488 on the top level and 0.958 in the end,
// and 3 levels miss it. The check counts the copies whose levels keep less than the search's
// share, and the automatic model takes 2 levels.
TEST(PyramidDepthCheck, ADepthWhoseTopLevelKeepsTooLittleOfThePartIsGivenUp) {
  const cv::Mat templ = testPhoto("text_lines_template.png");
  const cv::Mat scene = testPhoto("text_lines_scene.png");
  ASSERT_FALSE(templ.empty());
  ASSERT_FALSE(scene.empty());
  ShapeModelParams three;
  three.numLevels = 3;
  const ShapeModel deep = createShapeModel(templ, three);
  EXPECT_TRUE(findShapeModel(scene, deep).empty())
      << "3 levels find the part: the test no longer shows what the check is for";
  EXPECT_GT(copiesLostBySearch(templ, deep), 0);

  const ShapeModel automatic = createShapeModel(templ);
  EXPECT_EQ(automatic.numLevels(), 2);
  ASSERT_EQ(automatic.pyramidTrials.size(), 2u);
  EXPECT_EQ(automatic.pyramidTrials[0].levels, 3);
  EXPECT_GT(automatic.pyramidTrials[0].copiesLost, 0);
  EXPECT_EQ(automatic.pyramidTrials[1].copiesLost, 0);
  const auto found = findShapeModel(scene, automatic);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_GT(found[0].score, 0.9);
  // Where the exhaustive search of level 0 alone finds it.
  ShapeModelParams one;
  one.numLevels = 1;
  const auto exhaustive = findShapeModel(scene, createShapeModel(templ, one));
  ASSERT_EQ(exhaustive.size(), 1u);
  EXPECT_LT(std::hypot(found[0].x - exhaustive[0].x, found[0].y - exhaustive[0].y), 0.05);
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
