// findShapeModel: accuracy of each subpixel mode and the effect of every search parameter, on
// generated scenes with exact ground truth.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/shape/nested_part_scenes.hpp"
#include "tests/shape/photo_occlusion.hpp"
#include "tests/shape/test_photos.hpp"

namespace facet {
namespace {

using testing::bracketScene;
using testing::bracketTemplate;
using testing::testPhoto;

const ShapeModel& bracketModel() {
  static const ShapeModel model = createShapeModel(bracketTemplate());
  return model;
}

double angleErrorDeg(const ShapeMatch& m, const Pose2D& truth) {
  return degrees(wrapAngle(m.angle - truth.angle));
}

double positionError(const ShapeMatch& m, const Pose2D& truth) {
  return std::hypot(m.x - truth.x, m.y - truth.y);
}

// The match close to `truth` (within 2 px), or nullptr.
const ShapeMatch* near(const std::vector<ShapeMatch>& matches, const Pose2D& truth) {
  for (const auto& m : matches)
    if (positionError(m, truth) < 2.0 && std::abs(angleErrorDeg(m, truth)) < 2.0) return &m;
  return nullptr;
}

TEST(FindShapeModel, LeastSquaresIsSubpixelAccurateAtAnyAngle) {
  const std::vector<Pose2D> poses = {{200.37, 150.81, radians(33.3), 1.0},
                                     {210.52, 160.14, radians(-151.7), 1.0},
                                     {190.05, 145.66, radians(97.25), 1.0}};
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const cv::Mat image = bracketScene({400, 300}, {poses[i]}, 10 + i);
    const auto matches = findShapeModel(image, bracketModel());
    ASSERT_EQ(matches.size(), 1u) << "pose " << i;
    EXPECT_LT(positionError(matches[0], poses[i]), 0.05) << "pose " << i;
    EXPECT_LT(std::abs(angleErrorDeg(matches[0], poses[i])), 0.03) << "pose " << i;
    // The default refinement may adjust a fixed scale by up to 2%; on an exact part it stays put.
    EXPECT_NEAR(matches[0].scale, 1.0, 1e-3);
    EXPECT_GT(matches[0].score, 0.9);
    EXPECT_LT(matches[0].residual, 0.2);
    // The contour is the model's subpixel points at the pose.
    ASSERT_EQ(matches[0].contour.size(), bracketModel().finePoints.size());
    const cv::Point2d expected = matches[0].pose().apply(bracketModel().finePoints[7].position);
    EXPECT_NEAR(matches[0].contour[7].x, expected.x, 1e-9);
    EXPECT_NEAR(matches[0].contour[7].y, expected.y, 1e-9);
  }
}

TEST(FindShapeModel, SubpixelModesRankByAccuracy) {
  const Pose2D truth{201.3, 149.6, radians(-61.4), 1.0};
  const cv::Mat image = bracketScene({400, 300}, {truth}, 21);
  FindParams p;
  p.subpixel = SubpixelMode::None;
  const auto none = findShapeModel(image, bracketModel(), p);
  p.subpixel = SubpixelMode::Interpolation;
  const auto interp = findShapeModel(image, bracketModel(), p);
  p.subpixel = SubpixelMode::LeastSquares;
  const auto ls = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(none.size(), 1u);
  ASSERT_EQ(interp.size(), 1u);
  ASSERT_EQ(ls.size(), 1u);
  // None: on the integer pixel grid and the level-0 angle grid.
  EXPECT_EQ(none[0].x, std::round(none[0].x));
  EXPECT_EQ(none[0].y, std::round(none[0].y));
  EXPECT_LT(positionError(none[0], truth), 1.5);
  EXPECT_LT(positionError(interp[0], truth), 0.6);
  EXPECT_NE(interp[0].x, std::round(interp[0].x));
  EXPECT_LT(positionError(ls[0], truth), 0.05);
  EXPECT_LT(std::abs(angleErrorDeg(ls[0], truth)), 0.03);
  EXPECT_LT(positionError(ls[0], truth), positionError(interp[0], truth));
}

TEST(FindShapeModel, PolarityModes) {
  const Pose2D truth{200.0, 150.0, radians(20.0), 1.0};
  // Inverted contrast: a dark part on a light background.
  const cv::Mat inverted = bracketScene({400, 300}, {truth}, 31, 50.0, 170.0);
  FindParams p;
  p.polarity = Polarity::Use;
  EXPECT_TRUE(findShapeModel(inverted, bracketModel(), p).empty());
  p.polarity = Polarity::IgnoreGlobal;
  auto m = findShapeModel(inverted, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.05);
  EXPECT_GT(m[0].score, 0.9);
  p.polarity = Polarity::IgnoreLocal;
  m = findShapeModel(inverted, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.05);

  // Locally inverted: the left half of the background is lighter than the part.
  scene::Scene s(testing::bracketSpec({400, 300}, 32));
  s.addPolygon({{0, 0}, {200, 0}, {200, 300}, {0, 300}}, 250.0, "background");
  scene::placePart(s, scene::bracketPart(), truth, 150.0, 50.0);
  const cv::Mat mixed = s.render();
  p.minScore = 0.8;
  p.polarity = Polarity::Use;
  EXPECT_TRUE(findShapeModel(mixed, bracketModel(), p).empty());
  p.polarity = Polarity::IgnoreGlobal;
  EXPECT_TRUE(findShapeModel(mixed, bracketModel(), p).empty());
  p.polarity = Polarity::IgnoreLocal;
  m = findShapeModel(mixed, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.1);
}

TEST(FindShapeModel, AngleRangeRestrictsResults) {
  const Pose2D upright{130.0, 150.0, radians(5.0), 1.0};
  const Pose2D turned{390.0, 150.0, radians(95.0), 1.0};
  const cv::Mat image = bracketScene({520, 300}, {upright, turned}, 41);
  FindParams p;
  p.numMatches = 0;
  ASSERT_EQ(findShapeModel(image, bracketModel(), p).size(), 2u);
  p.angleStart = radians(-20.0);
  p.angleExtent = radians(40.0);
  auto m = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NE(near(m, upright), nullptr);
  // The same restriction trained into the model.
  ShapeModelParams mp;
  mp.angleStart = radians(60.0);
  mp.angleExtent = radians(60.0);
  const ShapeModel restricted = createShapeModel(bracketTemplate(), mp);
  m = findShapeModel(image, restricted, FindParams{.numMatches = 0});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NE(near(m, turned), nullptr);
  // Disjoint requested and trained ranges: nothing to search.
  EXPECT_TRUE(findShapeModel(image, restricted, p).empty());
}

TEST(FindShapeModel, NumMatchesAndScoreOrder) {
  const std::vector<Pose2D> poses = {{110.0, 110.0, radians(10.0), 1.0},
                                     {330.0, 110.0, radians(-100.0), 1.0},
                                     {220.0, 300.0, radians(170.0), 1.0}};
  const cv::Mat image = bracketScene({440, 420}, poses, 51);
  FindParams p;
  p.numMatches = 0;
  const auto all = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(all.size(), 3u);
  for (const auto& pose : poses) EXPECT_NE(near(all, pose), nullptr);
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_GE(all[i - 1].score, all[i].score);
  p.numMatches = 2;
  const auto two = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_DOUBLE_EQ(two[0].score, all[0].score);
  EXPECT_DOUBLE_EQ(two[1].score, all[1].score);
  p.numMatches = 1;
  EXPECT_EQ(findShapeModel(image, bracketModel(), p).size(), 1u);
}

TEST(FindShapeModel, ThreadsDoNotChangeTheMatches) {
  // Several parts, one of them half hidden by a later one, and a low min score: many candidates
  // are tracked down the pyramid, in parallel with threads > 1.
  const std::vector<Pose2D> poses = {{110.3, 110.6, radians(10.0), 1.0},
                                     {330.8, 110.1, radians(-100.0), 1.0},
                                     {220.2, 300.7, radians(170.0), 1.0},
                                     {290.5, 250.4, radians(35.0), 1.0}};
  const cv::Mat image = bracketScene({440, 420}, poses, 52);
  for (SubpixelMode mode : {SubpixelMode::None, SubpixelMode::LeastSquares}) {
    FindParams p;
    p.numMatches = 0;
    p.minScore = 0.4;
    p.subpixel = mode;
    p.threads = 1;
    const auto sequential = findShapeModel(image, bracketModel(), p);
    ASSERT_GE(sequential.size(), 3u);
    for (int threads : {2, 4}) {
      p.threads = threads;
      const auto parallel = findShapeModel(image, bracketModel(), p);
      ASSERT_EQ(parallel.size(), sequential.size()) << threads << " threads";
      for (std::size_t i = 0; i < parallel.size(); ++i) {
        // Bit for bit: the same candidates in the same order, whatever ran where.
        EXPECT_EQ(parallel[i].x, sequential[i].x) << threads << " threads, match " << i;
        EXPECT_EQ(parallel[i].y, sequential[i].y) << threads << " threads, match " << i;
        EXPECT_EQ(parallel[i].angle, sequential[i].angle) << threads << " threads, match " << i;
        EXPECT_EQ(parallel[i].score, sequential[i].score) << threads << " threads, match " << i;
      }
    }
  }
}

TEST(FindShapeModel, MaxOverlapSuppressesOverlappingMatches) {
  // Two brackets side by side whose boxes overlap by about a quarter.
  const Pose2D left{150.0, 150.0, 0.0, 1.0};
  const Pose2D right{250.0, 150.0, 0.0, 1.0};
  const cv::Mat image = bracketScene({420, 300}, {left, right}, 61);
  FindParams p;
  p.numMatches = 0;
  p.minScore = 0.6;
  p.maxOverlap = 0.5;
  auto m = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_NE(near(m, left), nullptr);
  EXPECT_NE(near(m, right), nullptr);
  p.maxOverlap = 0.1;
  m = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NE(near(m, right), nullptr);  // the one on top is whole, so it scores higher
}

TEST(FindShapeModel, MinScoreAndOcclusion) {
  const Pose2D truth{200.0, 150.0, radians(-30.0), 1.0};
  scene::Scene s(testing::bracketSpec({400, 300}, 71));
  scene::placePart(s, scene::bracketPart(), truth, testing::kPartGrey, testing::kBackground);
  // Hide the right part of the bracket under a mid-grey strip.
  s.addPolygon({{215, 0}, {400, 0}, {400, 300}, {215, 300}}, 110.0, "occluder");
  const cv::Mat image = s.render();
  FindParams p;
  p.minScore = 0.4;
  auto m = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.1);
  EXPECT_LT(m[0].score, 0.8);
  p.minScore = std::min(1.0, m[0].score + 0.05);
  EXPECT_TRUE(findShapeModel(image, bracketModel(), p).empty());
}

TEST(FindShapeModel, ScaleRange) {
  const Pose2D truth{200.0, 160.0, radians(45.0), 1.07};
  const cv::Mat image = bracketScene({400, 320}, {truth}, 81);
  // A fixed-scale model does not accept a 7% larger part.
  EXPECT_TRUE(findShapeModel(image, bracketModel()).empty());
  ShapeModelParams mp;
  mp.scaleMin = 0.9;
  mp.scaleMax = 1.1;
  const ShapeModel scaled = createShapeModel(bracketTemplate(), mp);
  auto m = findShapeModel(image, scaled);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(m[0].scale, 1.07, 1e-3);
  EXPECT_LT(positionError(m[0], truth), 0.05);
  EXPECT_LT(std::abs(angleErrorDeg(m[0], truth)), 0.03);
  // A requested range that excludes the part's scale.
  FindParams p;
  p.scaleMin = 0.9;
  p.scaleMax = 1.0;
  EXPECT_TRUE(findShapeModel(image, scaled, p).empty());
}

TEST(FindShapeModel, GreedinessAndLevelsKeepTheResult) {
  const Pose2D truth{180.3, 140.7, radians(123.0), 1.0};
  const cv::Mat image = bracketScene({400, 300}, {truth}, 91);
  for (double g : {0.0, 0.5, 1.0}) {
    FindParams p;
    p.greediness = g;
    const auto m = findShapeModel(image, bracketModel(), p);
    ASSERT_EQ(m.size(), 1u) << "greediness " << g;
    EXPECT_LT(positionError(m[0], truth), 0.05) << "greediness " << g;
  }
  FindParams p;
  p.numLevels = 2;
  p.threads = 1;
  const auto m = findShapeModel(image, bracketModel(), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.05);
}

TEST(FindShapeModel, MinContrastIgnoresWeakGradients) {
  // A faint part: contrast 30 grey levels, edge gradients of about 12 grey levels per pixel.
  const Pose2D truth{200.4, 150.3, radians(70.0), 1.0};
  const cv::Mat faint = bracketScene({400, 300}, {truth}, 97, testing::kBackground + 30.0);
  auto m = findShapeModel(faint, bracketModel());  // model minContrast 5
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.1);
  ShapeModelParams strict;
  strict.minContrast = 20.0;
  const ShapeModel model = createShapeModel(bracketTemplate(), strict);
  EXPECT_DOUBLE_EQ(model.minContrast, 20.0);
  EXPECT_TRUE(findShapeModel(faint, model).empty());
  // The strong part is still found with the strict model.
  m = findShapeModel(bracketScene({400, 300}, {truth}, 98), model);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.05);
}

TEST(FindShapeModel, SixteenBitImage) {
  const Pose2D truth{200.6, 150.2, radians(-10.0), 1.0};
  const auto m = findShapeModel(
      bracketScene({400, 300}, {truth}, 95, testing::kPartGrey, testing::kBackground, CV_16U),
      bracketModel());
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(positionError(m[0], truth), 0.05);
}

// Rigid, and with a deformation tolerance, which raises every score, clutter's too: it must still
// not make a part of it.
TEST(FindShapeModel, ClutterAloneGivesNoMatch) {
  for (const int deformation : {0, 2})
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      scene::Scene s(testing::bracketSpec({640, 480}, seed));
      s.addClutter(25, 10, 60, {});
      FindParams p;
      p.numMatches = 0;
      p.maxDeformation = deformation;
      EXPECT_TRUE(findShapeModel(s.render(), bracketModel(), p).empty())
          << "seed " << seed << ", max deformation " << deformation;
    }
}

TEST(FindShapeModel, EmptyImageAndBadParameters) {
  EXPECT_TRUE(findShapeModel(cv::Mat(), bracketModel()).empty());
  const cv::Mat image(100, 100, CV_8U, cv::Scalar(0));
  EXPECT_THROW(findShapeModel(image, ShapeModel{}), std::invalid_argument);
  EXPECT_THROW(findShapeModel(cv::Mat(10, 10, CV_8UC3), bracketModel()), std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.minScore = 0.0}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.numMatches = -1}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.maxOverlap = 1.5}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.greediness = -0.1}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.refineScaleTolerance = -0.01}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.refineScaleTolerance = 0.2}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.maxDeformation = -1}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(), FindParams{.maxDeformation = 9}),
               std::invalid_argument);
  EXPECT_THROW(findShapeModel(image, bracketModel(),
                              FindParams{.polarity = Polarity::IgnoreGlobal, .maxDeformation = 1}),
               std::invalid_argument);
  // An image smaller than the part: searched, nothing found, no crash.
  EXPECT_TRUE(findShapeModel(cv::Mat(20, 30, CV_8U, cv::Scalar(9)), bracketModel()).empty());
}

// A rectangular housing with a lens ring off its centre: on the top level (40 points) the half
// turn looks like the part, and the search used to keep only it there, returning the part turned
// by 180 deg at 0.73 or nothing at all at the default minimum, over most of the circle.
TEST(FindShapeModel, APartNearlySymmetricOnTheTopLevelIsFoundAtEveryAngle) {
  const ShapeModel model =
      createShapeModel(testing::nestedPartScene({140, 100}, {69.5, 49.5, 0.0, 1.0}, 5, false));
  ASSERT_GE(model.numLevels(), 4);
  // The half turn is a near-symmetry of the search, about the housing's centre (0.25, 0.15), not
  // about the centroid of the points, which the lens ring pulls aside.
  const auto halfTurn = std::find_if(
      model.symmetries.begin(), model.symmetries.end(),
      [](const ModelSymmetry& s) { return std::abs(std::abs(degrees(s.angle)) - 180.0) < 2.0; });
  ASSERT_NE(halfTurn, model.symmetries.end());
  EXPECT_NEAR(halfTurn->centre.x, 0.25, 1.0);
  EXPECT_NEAR(halfTurn->centre.y, 0.15, 1.0);
  for (int i = 0; i < 12; ++i) {
    const Pose2D truth{160.3 + 0.37 * i, 121.6 - 0.29 * i, radians(-165.0 + 30.0 * i), 1.0};
    const cv::Mat image = testing::nestedPartScene({320, 240}, truth, 200 + i, false);
    const auto matches = findShapeModel(image, model);
    ASSERT_EQ(matches.size(), 1u) << "angle " << degrees(truth.angle);
    EXPECT_NEAR(matches[0].x, truth.x, 0.05) << "angle " << degrees(truth.angle);
    EXPECT_NEAR(matches[0].y, truth.y, 0.05) << "angle " << degrees(truth.angle);
    EXPECT_NEAR(wrapAngle(matches[0].angle - truth.angle), 0.0, radians(0.05));
    EXPECT_GT(matches[0].score, 0.95);
  }
  // A range across +-180 deg given from 150 deg: the part at 165 deg is found, its half turn
  // lies outside the range.
  const Pose2D truth{161.1, 118.9, radians(165.0), 1.0};
  FindParams around;
  around.angleStart = radians(150.0);
  around.angleExtent = radians(50.0);
  const auto matches =
      findShapeModel(testing::nestedPartScene({320, 240}, truth, 300, false), model, around);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_NEAR(wrapAngle(matches[0].angle - truth.angle), 0.0, radians(0.05));
}

// Parts of a batch whose lens and frame sit 2.5 px apart from where the template has them, the
// housing in place (the LED photograph: a column of LEDs scored 0.3-0.7 and was missed).
// No rigid pose matches all three contours (a rigid match, where the search keeps one, scores
// less); with maxDeformation each model point may meet its edge up to that far off, the part is
// found, and the least-squares fit places it within the deformation of the housing. On parts that
// are exact copies the pose is the rigid search's.
TEST(FindShapeModel, APartWhoseContoursDifferFromTheTemplatesIsFoundWithAMaxDeformation) {
  const ShapeModel model =
      createShapeModel(testing::nestedPartScene({140, 100}, {69.5, 49.5, 0.0, 1.0}, 5, false));
  FindParams deformable;
  deformable.maxDeformation = 3;
  for (int i = 0; i < 8; ++i) {
    const Pose2D truth{160.3 + 0.37 * i, 121.6 - 0.29 * i, radians(-165.0 + 45.0 * i), 1.0};
    const cv::Point2d shift = i % 2 == 0 ? cv::Point2d(-1.5, 2.0) : cv::Point2d(1.8, -1.8);
    const cv::Mat image = testing::nestedPartScene({320, 240}, truth, 400 + i, false, shift);
    const auto rigidly = findShapeModel(image, model);
    const auto found = findShapeModel(image, model, deformable);
    ASSERT_EQ(found.size(), 1u) << "part " << i;
    EXPECT_GT(found[0].score, 0.9) << "part " << i;
    if (!rigidly.empty()) {
      EXPECT_LT(rigidly[0].score, found[0].score - 0.02) << "part " << i;
    }
    EXPECT_LT(std::hypot(found[0].x - truth.x, found[0].y - truth.y),
              std::hypot(shift.x, shift.y) + 0.5)
        << "part " << i;
    EXPECT_NEAR(wrapAngle(found[0].angle - truth.angle), 0.0, radians(0.5)) << "part " << i;

    const cv::Mat exact = testing::nestedPartScene({320, 240}, truth, 500 + i, false);
    const auto rigid = findShapeModel(exact, model);
    const auto tolerant = findShapeModel(exact, model, deformable);
    ASSERT_EQ(rigid.size(), 1u);
    ASSERT_EQ(tolerant.size(), 1u);
    EXPECT_NEAR(tolerant[0].x, rigid[0].x, 1e-6) << "part " << i;
    EXPECT_NEAR(tolerant[0].y, rigid[0].y, 1e-6) << "part " << i;
    EXPECT_NEAR(tolerant[0].angle, rigid[0].angle, 1e-8) << "part " << i;
    EXPECT_GE(tolerant[0].score, rigid[0].score - 1e-9);
  }
}

// The bracket 40% hidden behind a strip of grey 110, clutter around, at a pose drawn from `seed`.
struct OccludedScene {
  cv::Mat image;
  Pose2D truth;
};
OccludedScene occludedBracket(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  scene::Scene s(testing::bracketSpec({400, 300}, seed));
  const Pose2D truth{150 + 100 * u(rng), 120 + 60 * u(rng), (2 * u(rng) - 1) * 3.14159, 1.0};
  const cv::Rect2d box =
      scene::placePart(s, scene::bracketPart(), truth, testing::kPartGrey, testing::kBackground);
  s.addOccluder(box, 0.4, 110.0);
  s.addClutter(6, 10, 60, {box}, 0, 255);
  return {s.render(), truth};
}

// The occluder's edges pull the refinement's free scale beyond its 2% tolerance; refitted at the
// model's scale it lands on the part (0.05 and 0.11 px off) with more points on edges than at the
// scale the free fit wanted. That refit used to be judged by the score alone, and the interpolated
// start, 1.7 and 0.9 px off, was returned.
TEST(FindShapeModel, AScalePulledByAnOccluderDoesNotKeepTheRoughStart) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  FindParams p;
  p.minScore = 0.5;
  for (const std::uint64_t seed : {80u, 86u}) {
    const OccludedScene sc = occludedBracket(seed);
    const auto m = findShapeModel(sc.image, model, p);
    ASSERT_EQ(m.size(), 1u) << "seed " << seed;
    const double e = std::hypot(m[0].x - sc.truth.x, m[0].y - sc.truth.y);
    EXPECT_LT(e, 0.15) << "seed " << seed;
    EXPECT_GT(m[0].residual, 0.0) << "the refined pose, not the start";
  }
}

// An occluder's border parallel to a hidden edge of the part lets a free scale stand it in for
// that edge: the fit with the scale free went to 1.016-1.019 and 1.0-1.4 px off, ten times the
// residual of the fit at the model's scale, which lands on the part. And beside the occluder the
// search's rough pose, 1.2-1.6 px off, outscores the true one by 0.10-0.14, more than a
// refinement may give up unless it lays the part's points exactly on edges, which it does here.
// Both used to return poses 1.0-1.6 px off.
TEST(FindShapeModel, AnOccluderStandingInForAHiddenEdgeDoesNotMoveThePose) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  FindParams p;
  p.minScore = 0.5;
  for (const std::uint64_t seed : {15u, 63u, 76u, 184u, 78u, 134u, 181u}) {
    const OccludedScene sc = occludedBracket(seed);
    const auto m = findShapeModel(sc.image, model, p);
    ASSERT_EQ(m.size(), 1u) << "seed " << seed;
    const double e = std::hypot(m[0].x - sc.truth.x, m[0].y - sc.truth.y);
    EXPECT_LT(e, 0.1) << "seed " << seed;
    EXPECT_NEAR(m[0].scale, 1.0, 2e-3) << "seed " << seed;
    EXPECT_GT(m[0].residual, 0.0) << "seed " << seed << ": the refined pose, not the start";
  }
}

// With the scale held (refineScaleTolerance 0) a refinement that lays the visible part exactly on
// its edges is kept although the rough pose beside the occluder scores a little higher; it used to
// be judged by the score alone and the rough pose, 0.4-0.9 px off, was returned.
TEST(FindShapeModel, AHeldScaleKeepsAnExactRefinementBesideAnOccluder) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  FindParams p;
  p.minScore = 0.5;
  p.refineScaleTolerance = 0.0;
  for (const std::uint64_t seed : {23u, 33u, 72u, 86u}) {
    const OccludedScene sc = occludedBracket(seed);
    const auto m = findShapeModel(sc.image, model, p);
    ASSERT_EQ(m.size(), 1u) << "seed " << seed;
    EXPECT_LT(std::hypot(m[0].x - sc.truth.x, m[0].y - sc.truth.y), 0.15) << "seed " << seed;
    EXPECT_EQ(m[0].scale, 1.0) << "seed " << seed;
    EXPECT_GT(m[0].residual, 0.0) << "seed " << seed << ": the refined pose, not the start";
  }
}

// A part 40% hidden can peak on the top pyramid level one to three of that level's angle steps
// from its own angle, where the occluder's straight borders line up with the model's edges. The
// level below looked only half a top step either side, and the part was lost on the way down
// (no match, or a match 3-5 px and 3-4 degrees off). A second, wider look (two top steps) is
// tracked beside the near one. These seeds of the generator were missed before; all score above
// the minimum at their true pose.
TEST(FindShapeModel, AHiddenPartWhoseTopLevelPeakLiesStepsOffItsAngleIsFound) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  FindParams p;
  p.minScore = 0.5;
  for (const std::uint64_t seed : {44u, 169u, 303u, 379u, 402u, 502u, 700u, 755u, 897u}) {
    const OccludedScene sc = occludedBracket(seed);
    const auto m = findShapeModel(sc.image, model, p);
    ASSERT_EQ(m.size(), 1u) << "seed " << seed;
    EXPECT_LT(std::hypot(m[0].x - sc.truth.x, m[0].y - sc.truth.y), 0.1) << "seed " << seed;
    EXPECT_NEAR(wrapAngle(m[0].angle - sc.truth.angle), 0.0, radians(0.1)) << "seed " << seed;
  }
  // The same on a photograph: board_dip (tests/data/photos/cases.txt) with its left third hidden
  // behind a plate was not found at all.
  const std::string dir = FACET_TEST_DATA_DIR "/photos/";
  const cv::Mat templ = cv::imread(dir + "board_dip_template.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat scene = cv::imread(dir + "board_dip_scene.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(templ.empty() || scene.empty()) << "missing " << dir;
  const Pose2D truth{503.685, 428.379, radians(171.5), 1.01};
  const cv::Mat hidden = testing::hideSide(scene, templ.size(), truth, testing::HiddenSide::Left);
  const auto m = findShapeModel(hidden, createShapeModel(templ), p);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(std::hypot(m[0].x - truth.x, m[0].y - truth.y), 0.1);
  EXPECT_NEAR(wrapAngle(m[0].angle - truth.angle), 0.0, radians(0.1));
}

// A small part on a busy photograph: board_crystal (tests/data/photos/cases.txt, a crystal of
// 82x40 px on a circuit board) with its left or right third hidden behind a plate. Its top level
// (20x10 px) ranks the part 100th-220th among the clutter's peaks; the search kept the first 30
// and returned nothing, although the part scores 0.71 and 0.76 at level 0. Every top-level peak
// is tracked now, and the one match asked for is the part, as when all matches are asked for.
TEST(FindShapeModel, ASmallPartBehindManyTopLevelPeaksOfClutterIsFound) {
  const std::string dir = FACET_TEST_DATA_DIR "/photos/";
  const cv::Mat templ = cv::imread(dir + "board_crystal_template.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat scene = cv::imread(dir + "board_crystal_scene.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(templ.empty() || scene.empty()) << "missing " << dir;
  const Pose2D truth{327.085, 143.753, radians(71.0), 1.0};
  const ShapeModel model = createShapeModel(templ);
  FindParams one, all;
  one.minScore = all.minScore = 0.5;
  all.numMatches = 0;
  for (const testing::HiddenSide side : {testing::HiddenSide::Left, testing::HiddenSide::Right}) {
    const cv::Mat hidden = testing::hideSide(scene, templ.size(), truth, side);
    const auto m = findShapeModel(hidden, model, one);
    ASSERT_EQ(m.size(), 1u) << "side " << static_cast<int>(side);
    EXPECT_LT(std::hypot(m[0].x - truth.x, m[0].y - truth.y), 0.1);
    EXPECT_NEAR(wrapAngle(m[0].angle - truth.angle), 0.0, radians(0.2));
    EXPECT_GT(m[0].score, 0.7);
    const auto every = findShapeModel(hidden, model, all);
    ASSERT_FALSE(every.empty());
    EXPECT_NEAR(every[0].x, m[0].x, 1e-9);
    EXPECT_NEAR(every[0].score, m[0].score, 1e-9);
  }
}

// A photograph (tests/data/photos, stuff_lighter: the lighter turned by a known pose, scale 1.01)
// with a third of the part hidden behind a flat plate, from each side in turn. Hidden from the
// left, the plate's border pulled the free scale to 0.94 and the fit at the model's scale lay
// 0.45 px off; the pose returned was 0.50 px off. Neither fit is exact on a photograph, so a
// third one leaves out the points with no image gradient near them at the start (0.17 px). With a
// plate of grey 128 instead of the photograph's median the same side ends 0.26 px off at scale
// 1.004: the border still pulls a little.
TEST(FindShapeModel, AnOccludersBorderOnAPhotographDoesNotPullThePose) {
  const std::string dir = FACET_TEST_DATA_DIR "/photos/";
  const cv::Mat templ = cv::imread(dir + "stuff_lighter_template.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat scene = cv::imread(dir + "stuff_lighter_scene.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(templ.empty() || scene.empty()) << "missing " << dir;
  const Pose2D truth{216.507, 334.066, radians(-52.0), 1.01};  // tests/data/photos/cases.txt
  const ShapeModel model = createShapeModel(templ);
  FindParams p;
  p.minScore = 0.5;
  for (std::size_t k = 0; k < std::size(testing::kHiddenSides); ++k) {
    const cv::Mat hidden = testing::hideSide(scene, templ.size(), truth, testing::kHiddenSides[k]);
    const auto m = findShapeModel(hidden, model, p);
    ASSERT_EQ(m.size(), 1u) << "side " << k;
    EXPECT_LT(std::hypot(m[0].x - truth.x, m[0].y - truth.y), 0.25) << "side " << k;
    EXPECT_NEAR(m[0].scale, truth.scale, 0.005) << "side " << k;
  }
}

// A photograph of tests/data/photos turned about its centre (cubic), with noise of sigma 1.5 drawn
// from `noiseSeed` (none for 0), and where the centre of `region` lands in it.
struct TurnedPhoto {
  cv::Mat scene;
  cv::Point2d centre;
};
TurnedPhoto turnedPhoto(const cv::Mat& photo, const cv::Rect& region, double angleDeg, double scale,
                        int noiseSeed) {
  const cv::Mat turn = cv::getRotationMatrix2D(
      cv::Point2f((photo.cols - 1) / 2.0F, (photo.rows - 1) / 2.0F), angleDeg, scale);
  TurnedPhoto out;
  cv::warpAffine(photo, out.scene, turn, photo.size(), cv::INTER_CUBIC, cv::BORDER_CONSTANT,
                 cv::mean(photo));
  if (noiseSeed > 0) {
    cv::Mat noise(photo.size(), CV_32F), sum;
    cv::setRNGSeed(noiseSeed);
    cv::randn(noise, 0.0, 1.5);
    out.scene.convertTo(sum, CV_32F);
    sum += noise;
    sum.convertTo(out.scene, CV_8U);
  }
  const cv::Matx23d m = turn;
  const cv::Point2d c(region.x + (region.width - 1) / 2.0, region.y + (region.height - 1) / 2.0);
  out.centre = {m(0, 0) * c.x + m(0, 1) * c.y + m(0, 2), m(1, 0) * c.x + m(1, 1) * c.y + m(1, 2)};
  return out;
}

// The search's one match is the region of the turned photograph, within 0.1 px and 0.1 degrees.
void expectTheRegion(const ShapeModel& model, const TurnedPhoto& turned, double angleDeg,
                     double scale, double minScore) {
  const auto found = findShapeModel(turned.scene, model);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(std::hypot(found[0].x - turned.centre.x, found[0].y - turned.centre.y), 0.1);
  EXPECT_NEAR(found[0].angle, radians(angleDeg), radians(0.1));
  EXPECT_NEAR(found[0].scale, scale, 0.002);
  EXPECT_GT(found[0].score, minScore);
}

// expectTheRegion on copies of `photo` turned by `angleDeg` at `scale`, one per noise seed.
void expectTheRegionInTurnedCopies(const cv::Mat& photo, const cv::Rect& region,
                                   const ShapeModel& model, double angleDeg, double scale,
                                   std::initializer_list<int> seeds, double minScore) {
  for (const int seed : seeds) {
    SCOPED_TRACE("noise seed " + std::to_string(seed));
    expectTheRegion(model, turnedPhoto(photo, region, angleDeg, scale, seed), angleDeg, scale,
                    minScore);
  }
}

// A texture (tests/data/photos/baboon.png: fur) turned by -96.88 degrees, with noise: on the top
// pyramid level the best angle at the part's pixel lay 2.3 of that level's steps from the part's,
// the usual look on the level below found nothing there (0.47), and the part, scoring 0.99, was
// missed. The wider look below the top is taken from such a candidate too.
TEST(FindShapeModel, ATexturedPartWhoseTopLevelAngleIsOffIsFound) {
  const cv::Mat photo = testPhoto("baboon.png");
  ASSERT_FALSE(photo.empty());
  const cv::Rect region(129, 285, 88, 107);
  const ShapeModel model = createShapeModel(photo(region));
  expectTheRegionInTurnedCopies(photo, region, model, -96.88, 1.0, {3, 4, 5}, 0.95);
}

// A model trained on a region of a photograph with `levels` pyramid levels (0 = automatic).
ShapeModel regionModel(const cv::Mat& photo, cv::Rect region, int levels) {
  ShapeModelParams params;
  params.roi = region;
  params.numLevels = levels;
  return createShapeModel(photo, params);
}

// A region of a photograph with `margin` pixels of its border repeated around it, turned about
// the region's centre by `degrees` and shifted by `shift` (cubic): the copy and where the
// region's centre lies in it.
struct RegionCopy {
  cv::Mat image;
  cv::Point2d centre;
};
RegionCopy turnedRegion(const cv::Mat& photo, cv::Rect region, int margin, double degrees,
                        cv::Point2d shift) {
  cv::Mat canvas;
  cv::copyMakeBorder(photo(region), canvas, margin, margin, margin, margin, cv::BORDER_REPLICATE);
  const cv::Point2d centre(margin + (region.width - 1) / 2.0, margin + (region.height - 1) / 2.0);
  cv::Mat warp = cv::getRotationMatrix2D(centre, degrees, 1.0);
  warp.at<double>(0, 2) += shift.x;
  warp.at<double>(1, 2) += shift.y;
  RegionCopy copy;
  cv::warpAffine(canvas, copy.image, warp, canvas.size(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  copy.centre = centre + shift;
  return copy;
}

// A patch of orange peel (tests/data/photos/orange.png) turned by 58.5 degrees and shifted by
// 1.5 px, searched with 3 levels: levels 1 and 2 keep only the orange's outline (30 points against
// level 0's 449), level 1 left the angle 2.6 degrees off, three steps of level 0, where the peel's
// texture no longer scores, and the part (0.90) was missed. A candidate that fails its near look
// on any level looks two steps of the level above wide.
TEST(FindShapeModel, ATexturedPartWhoseOutlineAloneSetsTheAngleAboveIsFound) {
  const cv::Mat photo = testPhoto("orange.png");
  ASSERT_FALSE(photo.empty());
  const cv::Rect region(55, 109, 111, 77);
  const ShapeModel model = regionModel(photo, region, 3);
  ASSERT_LT(model.levels[1].points.size() * 4, model.levels[0].points.size());
  const RegionCopy copy = turnedRegion(photo, region, 36, 58.5, {0.0, 1.5});
  const auto found = findShapeModel(copy.image, model);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(std::hypot(found[0].x - copy.centre.x, found[0].y - copy.centre.y), 0.2);
  EXPECT_NEAR(found[0].angle, radians(58.5), radians(0.2));
  EXPECT_GT(found[0].score, 0.85);
}

// A larger patch of the orange, turned by -121.5 degrees and shifted by (1, 1.75) px, searched with
// 2 levels: level 1 peaks (0.88) 1.4 degrees and a pixel of its own from the part, the near look
// below fails, and the wider look, over 3x3 positions, missed the part (0.92) two pixels away.
// From a candidate that reached the minimum score above, the wider look covers the near look's
// 5x5 positions. The automatic pyramid, which searches such copies, had given this part one level
// (its search 10-70 times slower).
TEST(FindShapeModel, ATexturedDiscWhoseTopLevelPeakIsAPixelOffIsFound) {
  const cv::Mat photo = testPhoto("orange.png");
  ASSERT_FALSE(photo.empty());
  const cv::Rect region(144, 279, 159, 103);
  const ShapeModel model = regionModel(photo, region, 2);
  const RegionCopy copy = turnedRegion(photo, region, 48, -121.5, {1.0, 1.75});
  // The search's pose, not the least-squares fit's: on this texture the fit moves it by 0.4-0.75
  // px (from the known pose too), which is the refinement's matter, not the search's.
  FindParams find;
  find.subpixel = SubpixelMode::Interpolation;
  const auto found = findShapeModel(copy.image, model, find);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(std::hypot(found[0].x - copy.centre.x, found[0].y - copy.centre.y), 0.3);
  EXPECT_NEAR(found[0].angle, radians(-121.5), radians(0.3));
  EXPECT_GT(found[0].score, 0.85);

  EXPECT_EQ(regionModel(photo, region, 0).numLevels(), 2);
}

// A calibration chessboard photographed at an angle (tests/data/photos/left12.png), turned by
// -134.84 degrees at scale 1.01: on the top pyramid level the squares' quarter turns score almost
// as high as the part's own angle, and beside the part's pixel a quarter turn scored higher. Kept
// as the only peak there, it was tracked to a neighbouring square's pose (0.87, 67 px off) while
// the part scored 0.999. The second peak in angle is a candidate too.
TEST(FindShapeModel, APartWhoseTopLevelScorePeaksAtAQuarterTurnIsFound) {
  const cv::Mat photo = testPhoto("left12.png");
  ASSERT_FALSE(photo.empty());
  const cv::Rect region(247, 171, 149, 129);
  const ShapeModel model = createShapeModel(photo(region));
  expectTheRegionInTurnedCopies(photo, region, model, -134.84, 1.01, {0, 1}, 0.99);
}

// Another patch of the chessboard, turned by 82.13 degrees: on the top pyramid level (1/16) the
// part's pixel lay on a ridge of the score rising to a neighbouring square's peak 3 px away, and
// was suppressed by the ridge's next pixel, which that peak suppressed in turn; the square was
// returned (0.82) and the part (0.999) missed. The top level's maxima over position are kept by
// greedy suppression, which keeps the part's.
TEST(FindShapeModel, APartOnARidgeOfTheTopLevelScoreIsFound) {
  const cv::Mat photo = testPhoto("left12.png");
  ASSERT_FALSE(photo.empty());
  const cv::Rect region(306, 173, 176, 144);
  const ShapeModel model = createShapeModel(photo(region));
  expectTheRegionInTurnedCopies(photo, region, model, 82.13, 1.0, {0, 1}, 0.99);
}

// A chessboard patch whose model has near-symmetric turns (its top level maps onto itself at
// about 80 degrees either way), turned by -56.13 degrees: on the top level a neighbouring square
// at a half turn suppressed the part's pixel, and nothing was returned while the part scores
// 0.999. The second peaks in angle were off for models with near-symmetries; they are off now
// only for a model that every turn maps onto itself.
TEST(FindShapeModel, ANearSymmetricPartBesideAHalfTurnOfItsPatternIsFound) {
  const cv::Mat photo = testPhoto("left12.png");
  ASSERT_FALSE(photo.empty());
  const cv::Rect region(334, 102, 174, 160);
  const ShapeModel model = createShapeModel(photo(region));
  ASSERT_FALSE(model.symmetries.empty());
  expectTheRegionInTurnedCopies(photo, region, model, -56.13, 1.0, {0, 1}, 0.99);
}

// The photograph of 36 packaged LEDs (tests/data/photos, case leds; reference positions by NCC).
// Its third column has the lens set 2-3 px off-centre in the housing against the template: rigidly
// those parts score 0.3-0.7 and are missed at the default minimum, the other 27 are found. With a
// tolerance of one pixel all 36 are, nothing else. Where lens and housing disagree the pose is
// the contours' compromise: within 5 px of NCC's peak (the other columns within 2 px).
TEST(FindShapeModel, LedsWithTheirLensOffCentreAreFoundWithAMaxDeformationOfOnePixel) {
  const std::string dir = FACET_TEST_DATA_DIR "/photos/";
  const cv::Mat templ = cv::imread(dir + "leds_template.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat scene = cv::imread(dir + "leds.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(templ.empty() || scene.empty()) << "missing " << dir;
  // The references: cases.txt's line "leds template scene period count (x y angle scale)...".
  std::vector<cv::Point2d> refs;
  std::ifstream cases(dir + "cases.txt");
  for (std::string line; std::getline(cases, line);) {
    std::istringstream in(line);
    std::string name, t, s;
    int period = 0, count = 0;
    if (!(in >> name >> t >> s >> period >> count) || name != "leds") continue;
    for (int i = 0; i < count; ++i) {
      double x, y, a, sc;
      in >> x >> y >> a >> sc;
      refs.emplace_back(x, y);
    }
  }
  ASSERT_EQ(refs.size(), 36u);
  // The reference within `reach` of a match (-1: none); the third column lies at x > 1000.
  auto refNear = [&](const ShapeMatch& m, double reach) {
    for (std::size_t i = 0; i < refs.size(); ++i)
      if (std::hypot(m.x - refs[i].x, m.y - refs[i].y) < reach) return static_cast<int>(i);
    return -1;
  };
  auto inThirdColumn = [](const cv::Point2d& r) { return r.x > 1000.0 && r.x < 1200.0; };

  const ShapeModel model = createShapeModel(templ);
  FindParams p;
  p.numMatches = 0;
  const auto rigid = findShapeModel(scene, model, p);
  EXPECT_GE(rigid.size(), 25u);
  for (const ShapeMatch& m : rigid) {
    const int r = refNear(m, 2.0);
    ASSERT_GE(r, 0) << "a match off the LEDs at " << m.x << "," << m.y;
    EXPECT_FALSE(inThirdColumn(refs[static_cast<std::size_t>(r)])) << m.x << "," << m.y;
  }

  p.maxDeformation = 1;
  const auto tolerant = findShapeModel(scene, model, p);
  std::vector<bool> found(refs.size(), false);
  for (const ShapeMatch& m : tolerant) {
    const int r = refNear(m, 5.0);
    ASSERT_GE(r, 0) << "a match off the LEDs at " << m.x << "," << m.y;
    EXPECT_FALSE(found[static_cast<std::size_t>(r)]) << "found twice: " << refs[r];
    found[static_cast<std::size_t>(r)] = true;
    if (!inThirdColumn(refs[static_cast<std::size_t>(r)])) {
      EXPECT_LT(std::hypot(m.x - refs[r].x, m.y - refs[r].y), 2.0) << m.x << "," << m.y;
    }
    EXPECT_GT(m.score, 0.7);
  }
  EXPECT_EQ(std::count(found.begin(), found.end(), true), 36);
}

}  // namespace
}  // namespace facet
