// findShapeModel never makes things worse than it has to: early termination keeps every clear
// part; the least-squares refinement follows a part slightly larger than its template, never
// lowers the score of its start on a part held at a scale it does not have, and fits the part,
// not a hole out of place; the full search returns the best of the near-symmetric poses of a
// part.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/model_symmetry.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/support/scene/parts.hpp"

namespace facet {
namespace {

using testing::bracketScene;
using testing::bracketSpec;
using testing::bracketTemplate;

double positionError(const ShapeMatch& m, const Pose2D& truth) {
  return std::hypot(m.x - truth.x, m.y - truth.y);
}

// The default early termination may abandon a pose only when it cannot reach minScore. A model
// whose first tenth of points (in the order the search scores them) never matches still scores
// about 0.9 on a clean part, well above the default 0.7: it must be found.
TEST(FindShapeModelSafety, EarlyTerminationKeepsAClearPartWhosePrefixMisses) {
  ShapeModel model = createShapeModel(bracketTemplate());
  for (std::size_t l = 1; l < model.levels.size(); ++l) {
    auto& points = model.levels[l].points;
    const std::size_t spoiled = points.size() / 10;
    for (std::size_t i = 0; i < spoiled; ++i)
      points[i].direction = {-points[i].direction.y, points[i].direction.x};  // 90 deg off
  }
  {
    auto& points = model.levels[0].points;
    for (std::size_t i = 0; i < points.size() / 10; ++i)
      points[i].direction = {-points[i].direction.y, points[i].direction.x};
  }
  const Pose2D truth{201.4, 152.7, radians(23.0), 1.0};
  const auto matches = findShapeModel(bracketScene({400, 300}, {truth}, 5), model);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_LT(positionError(matches[0], truth), 0.1);
  EXPECT_GT(matches[0].score, 0.85);
}

// A part 1% larger than its template (the model has no scale range): the refinement adjusts
// the scale within its default tolerance, reports it, and keeps the position.
TEST(FindShapeModelSafety, RefinementFollowsASlightlyLargerPart) {
  const ShapeModel model = createShapeModel(bracketTemplate());
  const Pose2D truth{200.3, 150.6, radians(-41.0), 1.01};
  const cv::Mat image = bracketScene({400, 300}, {truth}, 8);
  const auto ls = findShapeModel(image, model);
  FindParams interp;
  interp.subpixel = SubpixelMode::Interpolation;
  const auto in = findShapeModel(image, model, interp);
  ASSERT_EQ(ls.size(), 1u);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_LT(positionError(ls[0], truth), 0.05);
  EXPECT_NEAR(ls[0].scale, 1.01, 1e-3);
  EXPECT_GE(ls[0].score, in[0].score);
  // Without the tolerance the scale stays fixed, and the score still never falls below the
  // start pose's.
  FindParams fixed;
  fixed.refineScaleTolerance = 0.0;
  const auto f = findShapeModel(image, model, fixed);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_DOUBLE_EQ(f[0].scale, 1.0);
  EXPECT_GE(f[0].score, in[0].score - 1e-9);
}

// A part 4% larger than the template is beyond the default tolerance: the refinement may not
// stretch the scale that far, and the pose it returns scores at least as well as its start.
TEST(FindShapeModelSafety, RefinementNeverLowersTheScore) {
  const ShapeModel model = createShapeModel(bracketTemplate());
  for (const double scale : {0.97, 1.04}) {
    const Pose2D truth{199.6, 149.2, radians(77.0), scale};
    const cv::Mat image = bracketScene({400, 300}, {truth}, 9);
    FindParams interp;
    interp.subpixel = SubpixelMode::Interpolation;
    interp.minScore = 0.5;
    FindParams ls;
    ls.minScore = 0.5;
    const auto in = findShapeModel(image, model, interp);
    const auto out = findShapeModel(image, model, ls);
    ASSERT_EQ(in.size(), 1u) << scale;
    ASSERT_EQ(out.size(), 1u) << scale;
    EXPECT_GE(out[0].score, in[0].score - 1e-9) << scale;
    EXPECT_LE(std::abs(out[0].scale - 1.0), 0.02 + 1e-9) << scale;
  }
}

// A part whose small hole is 10 px out of place (a drilling fault the inspection is there to
// find): the pose must come from the rest of the part. A pose tilted towards the displaced hole
// scores higher than the true one (it half-covers the hole's edges as well), so the refinement
// is judged by the model points it puts exactly on edges, not by the score.
TEST(FindShapeModelSafety, RefinementFitsThePartNotAHoleOutOfPlace) {
  const ShapeModel model = createShapeModel(bracketTemplate());
  scene::PartDrawing faulty = scene::bracketPart();
  faulty.primitives[2].centre.x += 10;  // the hole at (38, -27)
  int tilted = 0;
  for (const double angleDeg : {-23.0, 4.0, 19.5, 61.0}) {
    const Pose2D truth{200.4, 150.3, radians(angleDeg), 1.0};
    scene::Scene s(bracketSpec({400, 300}, 11));
    scene::placePart(s, faulty, truth, testing::kPartGrey, testing::kBackground);
    const auto found = findShapeModel(s.render(), model);
    FindParams interp;
    interp.subpixel = SubpixelMode::Interpolation;
    const auto coarse = findShapeModel(s.render(), model, interp);
    ASSERT_EQ(found.size(), 1u) << angleDeg;
    ASSERT_EQ(coarse.size(), 1u) << angleDeg;
    const double angleError = std::abs(found[0].angle - truth.angle) * 180 / CV_PI;
    EXPECT_LT(angleError, 0.02) << angleDeg << " deg";
    EXPECT_LT(positionError(found[0], truth), 0.05) << angleDeg << " deg";
    tilted += std::abs(coarse[0].angle - truth.angle) * 180 / CV_PI > 0.1;
  }
  // The case is real: the interpolated search pose is pulled off by the hole.
  EXPECT_GT(tilted, 0);
}

// A cross whose four arms differ by a few pixels: each quarter turn is a near match. The full
// search must return the exact one.
scene::PartDrawing nearSymmetricCross() {
  scene::PartDrawing part;
  scene::Primitive cross;
  cross.kind = scene::Primitive::Kind::Polygon;
  const double w = 11;  // half width of an arm
  const double right = 60, left = 57, up = 58, down = 55;
  cross.vertices = {{w, -up},   {w, -w}, {right, -w}, {right, w},  {w, w},   {w, down},
                    {-w, down}, {-w, w}, {-left, w},  {-left, -w}, {-w, -w}, {-w, -up}};
  part.primitives.push_back(cross);
  part.templateSize = {140, 134};
  return part;
}

// The near-symmetries the search tries: the cross's three quarter turns, the bracket none.
TEST(FindShapeModelSafety, ModelSymmetriesAreTheCrossQuarterTurnsAndNoneOfTheBracket) {
  const cv::Mat templ =
      scene::templateScene(nearSymmetricCross(), bracketSpec({}, 31), testing::kPartGrey).render();
  const ShapeModel cross = createShapeModel(templ);
  ASSERT_EQ(cross.symmetries.size(), 3u);
  std::vector<double> turns;
  for (const ModelSymmetry& s : cross.symmetries) {
    turns.push_back(degrees(s.angle));
    EXPECT_GT(s.score, 0.6);
    EXPECT_LT(s.score, 0.99);  // the arms differ: no exact symmetry
  }
  std::sort(turns.begin(), turns.end());
  EXPECT_NEAR(turns[0], -90, 1.0);
  EXPECT_NEAR(turns[1], 90, 1.0);
  EXPECT_NEAR(std::abs(turns[2]), 180, 1.0);
  EXPECT_TRUE(createShapeModel(bracketTemplate()).symmetries.empty());
}

// A disc maps onto itself at every turn (the search then seeks no second peaks in angle, its
// score being flat in angle); the near-symmetric cross and the bracket do not.
TEST(FindShapeModelSafety, OnlyADiscMapsOntoItselfAtEveryTurn) {
  cv::Mat disc(90, 90, CV_8U, cv::Scalar(60));
  cv::circle(disc, {45, 45}, 30, cv::Scalar(190), cv::FILLED, cv::LINE_AA);
  cv::GaussianBlur(disc, disc, {}, 1.0);
  const cv::Mat crossTemplate =
      scene::templateScene(nearSymmetricCross(), bracketSpec({}, 31), testing::kPartGrey).render();
  for (const auto& [templ, every] : std::vector<std::pair<cv::Mat, bool>>{
           {disc, true}, {crossTemplate, false}, {bracketTemplate(), false}}) {
    const ShapeModel model = createShapeModel(templ);
    for (const ShapeLevel& level : {model.levels.front(), model.levels.back()})
      EXPECT_EQ(mapsOntoItselfAtEveryTurn(level.points, level.angleStep), every)
          << templ.cols << "x" << templ.rows << " template, " << level.points.size() << " points";
  }
}

TEST(FindShapeModelSafety, FullSearchReturnsTheBestOfNearSymmetricPoses) {
  const scene::PartDrawing part = nearSymmetricCross();
  const cv::Mat templ =
      scene::templateScene(part, bracketSpec({}, 31), testing::kPartGrey).render();
  const ShapeModel model = createShapeModel(templ);
  int wrong = 0;
  for (int k = 0; k < 8; ++k) {
    const Pose2D truth{200.2 + k, 180.7 - k, radians(-170.0 + 45.3 * k), 1.0};
    scene::Scene s(bracketSpec({400, 360}, 40 + k));
    scene::placePart(s, part, truth, testing::kPartGrey, testing::kBackground);
    const auto matches = findShapeModel(s.render(), model);
    ASSERT_EQ(matches.size(), 1u) << "pose " << k;
    const double da = degrees(wrapAngle(matches[0].angle - truth.angle));
    if (std::abs(da) > 0.1 || positionError(matches[0], truth) > 0.1) {
      ++wrong;
      ADD_FAILURE() << "pose " << k << ": found " << degrees(matches[0].angle) << " deg at "
                    << matches[0].x << ", " << matches[0].y << " (score " << matches[0].score
                    << "), truth " << degrees(truth.angle) << " deg";
    }
  }
  EXPECT_EQ(wrong, 0);
}

}  // namespace
}  // namespace facet
