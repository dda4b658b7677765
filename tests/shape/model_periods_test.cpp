// The periods of a model's pattern within the top level's reach (findSearchPeriods,
// algorithms/shape/model_symmetry.hpp), which the automatic pyramid refuses, and those the search
// tracks beside each top-level candidate (findTrackedPeriods).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/model_symmetry.hpp"
#include "algorithms/shape/response_map_search.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/shape/test_photos.hpp"

namespace facet {
namespace {

constexpr int kSquare = 8;  // pixels

// A chessboard that goes on around the trained region, slightly blurred.
cv::Mat chessboard() {
  cv::Mat board(20 * kSquare, 20 * kSquare, CV_8U);
  for (int y = 0; y < board.rows; ++y)
    for (int x = 0; x < board.cols; ++x)
      board.at<std::uint8_t>(y, x) = ((x / kSquare + y / kSquare) % 2) ? 200 : 50;
  cv::GaussianBlur(board, board, {}, 0.8);
  return board;
}

const cv::Rect kRegion(6 * kSquare + 5, 7 * kSquare + 3, 70, 60);

ShapeModel modelOf(const cv::Mat& image, cv::Rect region, int levels) {
  ShapeModelParams params;
  params.roi = region;
  params.numLevels = levels;
  return createShapeModel(image, params);
}

// With 3 levels (a square is 2 px on the top level) the board's periods lie within the top
// level's reach: each is a shift that keeps the squares' colours (whole squares, an even number
// of them in x and y together).
TEST(ModelPeriods, AChessboardsPeriodsAreShiftsByWholeSquaresThatKeepTheColours) {
  const ShapeModel model = modelOf(chessboard(), kRegion, 3);
  const auto periods = findSearchPeriods(model.levels, shape_detail::kPeakReach);
  ASSERT_FALSE(periods.empty());
  for (const ModelPeriod& p : periods) {
    // Within a pixel and a half of a lattice point: the self-similarity's maximum on level 0's
    // pixel grid.
    const long i = std::lround(p.shift.x / kSquare), j = std::lround(p.shift.y / kSquare);
    EXPECT_NEAR(p.shift.x, i * kSquare, 1.5) << p.shift;
    EXPECT_NEAR(p.shift.y, j * kSquare, 1.5) << p.shift;
    EXPECT_EQ((i + j) % 2, 0) << p.shift;
    EXPECT_GE(std::hypot(p.shift.x, p.shift.y), 4.0);  // a pixel of the top level or more
    EXPECT_GT(p.score, 0.8);
  }
  // With 2 levels the shortest period (a diagonal, 11 px) lies beyond the top level's reach.
  EXPECT_TRUE(findSearchPeriods(modelOf(chessboard(), kRegion, 2).levels, shape_detail::kPeakReach)
                  .empty());
}

// Straight edges map onto themselves when shifted along them, but that is a slide, not a period:
// a rectangle and the bracket have none.
TEST(ModelPeriods, APartWithoutARepeatingPatternHasNone) {
  cv::Mat plate(120, 160, CV_8U, cv::Scalar(60));
  cv::rectangle(plate, cv::Rect(20, 30, 120, 60), cv::Scalar(190), cv::FILLED);
  cv::GaussianBlur(plate, plate, {}, 1.0);
  EXPECT_TRUE(findSearchPeriods(modelOf(plate, {}, 3).levels, shape_detail::kPeakReach).empty());
  const ShapeModel bracket = createShapeModel(testing::bracketTemplate());
  EXPECT_TRUE(findSearchPeriods(bracket.levels, shape_detail::kPeakReach).empty());
}

// The automatic pyramid refuses the depths whose top level sees the board's period and says so.
TEST(ModelPeriods, TheAutomaticPyramidRefusesATopLevelThatSeesThePeriod) {
  const ShapeModel model = modelOf(chessboard(), kRegion, 0);
  ASSERT_GE(model.pyramidTrials.size(), 2u);
  const PyramidTrial& refused = model.pyramidTrials.front();
  ASSERT_TRUE(refused.period.has_value());
  EXPECT_GT(refused.levels, model.numLevels());
  EXPECT_TRUE(findSearchPeriods(model.levels, shape_detail::kPeakReach).empty());
  EXPECT_FALSE(model.pyramidTrials.back().period.has_value());  // then the copies' test
  EXPECT_EQ(model.pyramidTrials.back().levels, model.numLevels());
}

// A patch of a chessboard photographed at a slant (tests/data/photos/slanted_board_*.png), the
// model trained from the cut-out patch: its squares' spacing changes across the patch, so one
// period maps only 0.63-0.68 of level 0's points onto like points and the automatic pyramid keeps
// 4 levels; on the top level (1/8) the slant is gone and a neighbouring square's pose two pixels
// from the part's outscores it (0.937 against 0.927). Tracked one period away, that candidate
// leads to the part.
TEST(ModelPeriods, APartBesideANeighbouringPeriodOnTheTopLevelIsFound) {
  const cv::Mat templ = testing::testPhoto("slanted_board_template.png");
  const cv::Mat scene = testing::testPhoto("slanted_board_scene.png");
  ASSERT_FALSE(templ.empty());
  ASSERT_FALSE(scene.empty());
  ShapeModel model = createShapeModel(templ);
  ASSERT_EQ(model.numLevels(), 4);
  ASSERT_FALSE(model.trackedPeriods.empty());
  // Where the scene's turn puts the template's centre (bench_turned_photos' case, README).
  const cv::Point2d truth(138.40, 123.50);
  const double truthDeg = -1.35;
  const auto found = findShapeModel(scene, model);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(std::hypot(found[0].x - truth.x, found[0].y - truth.y), 0.2);
  EXPECT_LT(std::abs(found[0].angle * 180.0 / std::numbers::pi - truthDeg), 0.2);
  EXPECT_GT(found[0].score, 0.99);

  model.trackedPeriods.clear();
  const auto untracked = findShapeModel(scene, model);
  ASSERT_FALSE(untracked.empty());
  EXPECT_GT(std::hypot(untracked[0].x - truth.x, untracked[0].y - truth.y), 10.0)
      << "the search finds the part without tracking the periods: the test no longer shows what "
         "they are for";
}

}  // namespace
}  // namespace facet
