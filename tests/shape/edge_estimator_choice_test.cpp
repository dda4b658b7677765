// The edge estimator a model's refinement uses, chosen at training by finding the template's own
// pose again on turned copies of it (algorithms/shape/edge_estimator_choice.hpp). Each choice is
// checked against scenes rendered at known poses, which the training test never saw.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core/utility.hpp>

#include "algorithms/shape/edge_estimator_choice.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/shape/nested_part_scenes.hpp"
#include "tests/shape/test_photos.hpp"

namespace facet {
namespace {

double trialError(const ShapeModel& model, EdgeEstimator estimator) {
  for (const EdgeEstimatorTrial& t : model.edgeEstimatorTrials)
    if (t.estimator == estimator) return t.poseError;
  ADD_FAILURE() << "no trial of this estimator";
  return NAN;
}

cv::Mat bracketTemplate(scene::BlurModel blur) {
  scene::SceneSpec spec = testing::bracketSpec({}, 99);
  spec.blurModel = blur;
  return scene::templateScene(scene::bracketPart(), spec, testing::kPartGrey).render();
}

// RMS over scenes of the position error of the first match (a scene not found counts as 10 px).
double positionRms(const ShapeModel& model, const std::vector<cv::Mat>& scenes,
                   const std::vector<Pose2D>& truths) {
  double sum = 0.0;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const auto matches = findShapeModel(scenes[i], model);
    const double e = matches.empty() ? 10.0
                                     : std::hypot(matches.front().x - truths[i].x,
                                                  matches.front().y - truths[i].y);
    sum += e * e;
  }
  return std::sqrt(sum / static_cast<double>(scenes.size()));
}

TEST(EdgeEstimatorChoice, BlurredStepsKeepTheProfileFitUnderBothBlurModels) {
  for (const auto blur : {scene::BlurModel::PixelGrid, scene::BlurModel::Lens}) {
    const ShapeModel model = createShapeModel(bracketTemplate(blur));
    EXPECT_EQ(model.edgeEstimator, EdgeEstimator::ProfileFit);
    ASSERT_EQ(model.edgeEstimatorTrials.size(), 2u);
    const double profile = trialError(model, EdgeEstimator::ProfileFit);
    EXPECT_LT(profile, 0.02) << "the turned copies are found to a fiftieth of a pixel";
    EXPECT_LT(profile, trialError(model, EdgeEstimator::FacetZeroCrossing));
  }
}

TEST(EdgeEstimatorChoice, SharpenedContoursAFewPixelsApartTakeTheZeroCrossingAndItIsRight) {
  const cv::Mat templ = testing::nestedPartScene({140, 100}, {69.5, 49.5, 0.0, 1.0}, 5, true);
  const ShapeModel chosen = createShapeModel(templ);
  ASSERT_EQ(chosen.edgeEstimator, EdgeEstimator::FacetZeroCrossing);
  EXPECT_LT(trialError(chosen, EdgeEstimator::FacetZeroCrossing),
            trialError(chosen, EdgeEstimator::ProfileFit));

  // Scenes the training test never saw: the part rendered at known poses.
  ShapeModelParams profileOnly;
  profileOnly.edgeEstimator = EdgeEstimator::ProfileFit;
  const ShapeModel profile = createShapeModel(templ, profileOnly);
  std::vector<cv::Mat> scenes;
  std::vector<Pose2D> truths;
  for (int i = 0; i < 6; ++i) {
    truths.push_back({150.3 + 7.37 * i, 118.6 - 5.13 * i, radians(-70.0 + 29.3 * i), 1.0});
    scenes.push_back(testing::nestedPartScene({320, 240}, truths.back(), 100 + i, true));
  }
  const double chosenRms = positionRms(chosen, scenes, truths);
  const double profileRms = positionRms(profile, scenes, truths);
  std::printf("position RMS over 6 scenes: zero crossing %.4f px, profile fit %.4f px\n", chosenRms,
              profileRms);
  EXPECT_LT(chosenRms, profileRms);
}

// A chip on a photographed circuit board (tests/data/photos/README.md, board_qfp44), trained on
// its region of the photograph: the zero crossing finds the turned copies a little better, within
// their scatter (where the profile fit was kept while a margin favoured it). It is chosen, and it
// is the better in a scene the trial never saw: the whole photograph turned by -117 degrees at
// scale 0.99, an exact reference.
TEST(EdgeEstimatorChoice, ThePhotographedChipTakesTheEstimatorThatFoundItsCopiesBetter) {
  const cv::Mat photo = testing::testPhoto("board_source.jpg");
  const cv::Mat scene = testing::testPhoto("board_qfp44_scene.png");
  ASSERT_FALSE(photo.empty() || scene.empty());
  ShapeModelParams region;
  region.roi = {300, 122, 68, 70};
  const ShapeModel chosen = createShapeModel(photo, region);
  const double zeroCrossingTrial = trialError(chosen, EdgeEstimator::FacetZeroCrossing);
  const double profileTrial = trialError(chosen, EdgeEstimator::ProfileFit);
  ASSERT_LT(zeroCrossingTrial, profileTrial);
  EXPECT_EQ(chosen.edgeEstimator, EdgeEstimator::FacetZeroCrossing);

  ShapeModelParams profileOnly = region;
  profileOnly.edgeEstimator = EdgeEstimator::ProfileFit;
  const ShapeModel profile = createShapeModel(photo, profileOnly);
  const std::vector<cv::Mat> scenes{scene};
  const std::vector<Pose2D> truths{{386.422, 289.154, radians(-117.0), 0.99}};
  const double chosenError = positionRms(chosen, scenes, truths);
  const double profileError = positionRms(profile, scenes, truths);
  std::printf(
      "trials: zero crossing %.4f px, profile fit %.4f px; in the scene: %.4f px, %.4f px\n",
      zeroCrossingTrial, profileTrial, chosenError, profileError);
  EXPECT_LT(chosenError, profileError);
  EXPECT_LT(chosenError, 0.05);
}

TEST(EdgeEstimatorChoice, AGivenEstimatorIsUsedWithoutTheTest) {
  ShapeModelParams params;
  params.edgeEstimator = EdgeEstimator::FacetZeroCrossing;
  const ShapeModel model = createShapeModel(bracketTemplate(scene::BlurModel::Lens), params);
  EXPECT_EQ(model.edgeEstimator, EdgeEstimator::FacetZeroCrossing);
  EXPECT_TRUE(model.edgeEstimatorTrials.empty());
}

// The turned copies are tried in parallel: the trials' errors, and so the choice, are the same
// on one thread as on several.
TEST(EdgeEstimatorChoice, TrialsAreTheSameOnOneThreadAndOnSeveral) {
  const cv::Mat templ = bracketTemplate(scene::BlurModel::Lens);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const ShapeModel serial = createShapeModel(templ);
  cv::setNumThreads(std::max(threads, 2));
  const ShapeModel parallel = createShapeModel(templ);
  cv::setNumThreads(threads);
  ASSERT_EQ(serial.edgeEstimatorTrials.size(), 2u);
  ASSERT_EQ(parallel.edgeEstimatorTrials.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(serial.edgeEstimatorTrials[i].estimator, parallel.edgeEstimatorTrials[i].estimator);
    EXPECT_EQ(serial.edgeEstimatorTrials[i].poseError, parallel.edgeEstimatorTrials[i].poseError);
  }
  EXPECT_EQ(serial.edgeEstimator, parallel.edgeEstimator);
}

}  // namespace
}  // namespace facet
