// createShapeModel: what a trained model holds, and how each training parameter shapes it.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_similarity.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/shape/test_photos.hpp"

namespace facet {
namespace {

using testing::bracketTemplate;

TEST(ShapeModel, DefaultModelHasAPyramidAndSubpixelPoints) {
  const ShapeModel model = createShapeModel(bracketTemplate());
  ASSERT_GE(model.numLevels(), 3);
  EXPECT_EQ(model.templateSize, cv::Size(160, 130));
  EXPECT_DOUBLE_EQ(model.referencePoint.x, 79.5);
  EXPECT_DOUBLE_EQ(model.referencePoint.y, 64.5);
  EXPECT_GT(model.levels[0].points.size(), 300u);
  EXPECT_LE(model.levels[0].points.size(), 800u);
  EXPECT_GT(model.finePoints.size(), 300u);
  // The bracket reaches about 82 px from its centre (corner (-65, 50)).
  EXPECT_NEAR(model.radius(), std::hypot(65.0, 50.0), 3.0);
  // Automatic angle step: the outermost point moves by about one pixel per step.
  EXPECT_NEAR(model.levels[0].angleStep, std::atan(1.0 / model.radius()), 1e-9);
  for (int l = 1; l < model.numLevels(); ++l) {
    EXPECT_GT(model.levels[l].angleStep, 1.8 * model.levels[l - 1].angleStep);
    EXPECT_LT(model.levels[l].points.size(), model.levels[l - 1].points.size());
    EXPECT_LE(model.levels[l].points.size(), 250u);
  }
  EXPECT_EQ(model.levels[0].scaleStep, 0.0);  // fixed scale
  // Directions are unit vectors, dark -> light: inside the plate's left edge (x = -65) they
  // point into the part (+x).
  int leftEdge = 0;
  for (const auto& p : model.finePoints) {
    EXPECT_NEAR(std::hypot(p.direction.x, p.direction.y), 1.0, 1e-3);
    if (std::abs(p.position.x + 65.0) < 0.5 && std::abs(p.position.y) < 40) {
      ++leftEdge;
      EXPECT_GT(p.direction.x, 0.95);
    }
  }
  EXPECT_GT(leftEdge, 20);
}

TEST(ShapeModel, RegionAndReferencePoint) {
  const cv::Mat templ = bracketTemplate();
  cv::Mat big(300, 400, CV_8U, cv::Scalar(testing::kBackground));
  templ.copyTo(big(cv::Rect(30, 20, templ.cols, templ.rows)));
  ShapeModelParams p;
  p.roi = cv::Rect(30, 20, templ.cols, templ.rows);
  const ShapeModel inRoi = createShapeModel(big, p);
  EXPECT_DOUBLE_EQ(inRoi.referencePoint.x, 79.5);
  EXPECT_DOUBLE_EQ(inRoi.referencePoint.y, 64.5);
  EXPECT_NEAR(inRoi.radius(), createShapeModel(templ).radius(), 0.5);

  p.referencePoint = cv::Point2d(30 + 79.5 + 10.0, 20 + 64.5);  // 10 px right of the centre
  const ShapeModel shifted = createShapeModel(big, p);
  EXPECT_DOUBLE_EQ(shifted.referencePoint.x, 89.5);
  // The same edges, 10 px further left of the new reference point.
  ASSERT_EQ(shifted.finePoints.size(), inRoi.finePoints.size());
  for (std::size_t i = 0; i < shifted.finePoints.size(); i += 10) {
    double nearest = 1e9;
    for (const auto& q : inRoi.finePoints)
      nearest = std::min(nearest, cv::norm(shifted.finePoints[i].position +
                                           cv::Point2f(10.0f, 0.0f) - q.position));
    EXPECT_LT(nearest, 1e-3);
  }

  p.roi = cv::Rect(300, 200, 200, 200);
  EXPECT_THROW(createShapeModel(big, p), ShapeModelError);
}

TEST(ShapeModel, MaskKeepsOnlyMaskedEdges) {
  const cv::Mat templ = bracketTemplate();
  ShapeModelParams p;
  p.mask = cv::Mat(templ.size(), CV_8U, cv::Scalar(0));
  p.mask(cv::Rect(0, 0, 80, templ.rows)).setTo(255);  // left half
  const ShapeModel model = createShapeModel(templ, p);
  for (const auto& pt : model.levels[0].points) EXPECT_LE(pt.position.x, 0.5);
  for (const auto& pt : model.finePoints) EXPECT_LE(pt.position.x, 1.0);
  p.mask = cv::Mat(10, 10, CV_8U, cv::Scalar(255));
  EXPECT_THROW(createShapeModel(templ, p), ShapeModelError);
}

TEST(ShapeModel, LevelsStepsScaleAndThinning) {
  const cv::Mat templ = bracketTemplate();
  ShapeModelParams p;
  p.numLevels = 2;
  p.angleStep = radians(1.0);
  p.scaleMin = 0.9;
  p.scaleMax = 1.1;
  p.maxPoints = 100;
  const ShapeModel model = createShapeModel(templ, p);
  ASSERT_EQ(model.numLevels(), 2);
  EXPECT_NEAR(model.levels[0].angleStep, radians(1.0), 1e-12);
  EXPECT_NEAR(model.levels[1].angleStep, radians(2.0), 1e-12);
  EXPECT_NEAR(model.levels[0].scaleStep, 1.0 / model.radius(), 1e-3);
  EXPECT_EQ(model.levels[0].points.size(), 100u);
  EXPECT_DOUBLE_EQ(model.scaleMin, 0.9);
  EXPECT_DOUBLE_EQ(model.scaleMax, 1.1);
}

TEST(ShapeModel, ContrastThresholds) {
  // The bracket (contrast 120) and a faint disc (contrast 60) in its corner.
  scene::Scene s =
      scene::templateScene(scene::bracketPart(), testing::bracketSpec({}, 99), testing::kPartGrey);
  s.addDisc({148, 118}, 7, testing::kBackground + 60);
  const cv::Mat templ = s.render();
  const ShapeModel automatic = createShapeModel(templ);
  EXPECT_GT(automatic.contrastHigh, 10.0);
  EXPECT_LT(automatic.contrastHigh, 60.0);  // an edge of 120 grey levels, blur 0.8: ~60 at its peak
  ShapeModelParams p;
  p.contrastLow = 30.0;
  p.contrastHigh = 40.0;
  const ShapeModel strict = createShapeModel(templ, p);
  EXPECT_DOUBLE_EQ(strict.contrastHigh, 40.0);
  EXPECT_LT(strict.levels[0].points.size(), automatic.levels[0].points.size());
  p.contrastLow = 900.0;
  p.contrastHigh = 1000.0;
  EXPECT_THROW(createShapeModel(templ, p), ShapeModelError);
}

TEST(ShapeModel, TemplateWithoutEdgesIsRefusedClearly) {
  scene::SceneSpec spec = testing::bracketSpec({160, 130}, 3);
  const cv::Mat flat = scene::Scene(spec).render();  // noise only
  try {
    createShapeModel(flat);
    FAIL() << "a template without edges must be refused";
  } catch (const ShapeModelError& e) {
    EXPECT_NE(std::string(e.what()).find("too few edges"), std::string::npos) << e.what();
  }
  EXPECT_THROW(createShapeModel(cv::Mat()), ShapeModelError);
  EXPECT_THROW(createShapeModel(cv::Mat(50, 50, CV_8UC3, cv::Scalar(0))), ShapeModelError);
  EXPECT_THROW(createShapeModel(cv::Mat(50, 50, CV_32F, cv::Scalar(0))), ShapeModelError);
  ShapeModelParams bad;
  bad.scaleMin = 0.0;
  EXPECT_THROW(createShapeModel(bracketTemplate(), bad), ShapeModelError);
}

// Places on the bracket's plate with no edge within 6 px: where a speck of dust would sit.
std::vector<cv::Point2d> plainPlaces(const cv::Mat& templ, std::size_t count) {
  std::vector<cv::Point2d> places;
  for (int y = 8; y < templ.rows - 8 && places.size() < count; y += 9)
    for (int x = 8; x < templ.cols - 8 && places.size() < count; x += 23) {
      double lo = 0.0, hi = 0.0;
      cv::minMaxLoc(templ(cv::Rect(x - 6, y - 6, 13, 13)), &lo, &hi);
      if (lo > testing::kPartGrey - 12 && hi < testing::kPartGrey + 12) places.emplace_back(x, y);
    }
  return places;
}

// A speck on the template (dust, a scratch, one sample's texture) is not on the next part: its
// contour would only lower that part's score in the search. The automatic minimum component
// leaves out contours of fewer than 10 pixels; 0 keeps them.
TEST(ShapeModel, SpecksOfOneSampleAreLeftOutOfTheModel) {
  scene::Scene speckled =
      scene::templateScene(scene::bracketPart(), testing::bracketSpec({}, 99), testing::kPartGrey);
  const std::vector<cv::Point2d> specks = plainPlaces(bracketTemplate(), 6);
  ASSERT_EQ(specks.size(), 6u);
  for (const cv::Point2d& c : specks) speckled.addDisc(c, 1.0, 60.0);
  const cv::Mat templ = speckled.render();

  const ShapeModel automatic = createShapeModel(templ);
  ShapeModelParams keepAll;
  keepAll.minComponentSize = 0;
  const ShapeModel everything = createShapeModel(templ, keepAll);
  EXPECT_EQ(automatic.minComponentSize, 10);
  EXPECT_EQ(everything.minComponentSize, 0);
  const auto pointsNearSpecks = [&](const ShapeModel& m) {
    int n = 0;
    for (const ShapePoint& p : m.levels[0].points)
      for (const cv::Point2d& c : specks)
        n += std::hypot(p.position.x + m.referencePoint.x - c.x,
                        p.position.y + m.referencePoint.y - c.y) < 3.0;
    return n;
  };
  EXPECT_GE(pointsNearSpecks(everything), 12);  // the specks do make edges
  EXPECT_EQ(pointsNearSpecks(automatic), 0);

  // Another sample, without the specks: the model without them sees more of it (the search's
  // score, on the level-0 points; the subpixel points have no edge on dots this small).
  const Pose2D truth{200.3, 150.6, 0.4, 1.0};
  const cv::Mat part = testing::bracketScene({400, 300}, {truth}, 17);
  FindParams searchOnly;
  searchOnly.subpixel = SubpixelMode::None;
  const auto a = findShapeModel(part, automatic, searchOnly);
  const auto e = findShapeModel(part, everything, searchOnly);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_GT(a[0].score, e[0].score + 0.03);
  EXPECT_LT(std::hypot(a[0].x - truth.x, a[0].y - truth.y), 1.0);
}

// A template made of small features only (a dot pattern): they are the part, and the automatic
// minimum keeps them; a minimum set by hand is applied as given.
TEST(ShapeModel, APatternOfDotsKeepsItsDots) {
  scene::SceneSpec spec = testing::bracketSpec({120, 100}, 5);
  scene::Scene dots(spec);
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 5; ++col)
      dots.addDisc({20.3 + 20.0 * col, 20.6 + 20.0 * row}, 1.0, testing::kPartGrey);
  const cv::Mat templ = dots.render();
  const ShapeModel model = createShapeModel(templ);
  EXPECT_EQ(model.minComponentSize, 0);
  EXPECT_GE(model.levels[0].points.size(), 150u);
  ShapeModelParams strict;
  strict.minComponentSize = 12;
  try {
    createShapeModel(templ, strict);
    ADD_FAILURE() << "a minimum that leaves no contour must be refused";
  } catch (const ShapeModelError& e) {
    EXPECT_NE(std::string(e.what()).find("contours of at least 12 pixels"), std::string::npos)
        << e.what();
  }
  strict.minComponentSize = -1;
  EXPECT_THROW(createShapeModel(bracketTemplate(), strict), ShapeModelError);
}

TEST(ShapeModel, SixteenBitTemplateGivesTheSameModel) {
  const ShapeModel m8 = createShapeModel(bracketTemplate(CV_8U));
  const ShapeModel m16 = createShapeModel(bracketTemplate(CV_16U));
  EXPECT_EQ(m8.numLevels(), m16.numLevels());
  EXPECT_NEAR(static_cast<double>(m16.levels[0].points.size()),
              static_cast<double>(m8.levels[0].points.size()), 0.1 * m8.levels[0].points.size());
  EXPECT_NEAR(m8.radius(), m16.radius(), 1.0);
}

// How far, at worst, a model's points on each level point away from the gradient of the image's own
// pyramid at their pixels (built as a search builds it, from the whole image), as the least dot
// product of the two unit directions; and how many points lie outside `region`.
struct LevelAgreement {
  std::vector<double> leastDot;
  int outside = 0;
};

LevelAgreement agreementWithImagePyramid(const cv::Mat& image, const ShapeModel& model,
                                         cv::Rect region, cv::Point reference) {
  LevelAgreement agreement;
  cv::Mat grey = shape_detail::toGreyFloat(image);
  for (int l = 0; l < model.numLevels(); ++l) {
    if (l > 0) cv::pyrDown(grey, grey);
    cv::Mat gx, gy;
    shape_detail::sobelGradients(grey, gx, gy);
    const cv::Rect onLevel(region.x >> l, region.y >> l, (region.width + (1 << l) - 1) >> l,
                           (region.height + (1 << l) - 1) >> l);
    double least = 1.0;
    for (const ShapePoint& p : model.levels[static_cast<std::size_t>(l)].points) {
      const cv::Point at(cvRound(p.position.x) + (reference.x >> l),
                         cvRound(p.position.y) + (reference.y >> l));
      if (!onLevel.contains(at)) {
        ++agreement.outside;
        continue;
      }
      const cv::Point2f g(gx.at<float>(at), gy.at<float>(at));
      least = std::min(least, static_cast<double>(g.dot(p.direction)) / cv::norm(g));
    }
    agreement.leastDot.push_back(least);
  }
  return agreement;
}

ShapeModel trainedInPlace(const cv::Mat& image, cv::Rect region, cv::Point reference) {
  ShapeModelParams inPlace;
  inPlace.roi = region;
  inPlace.referencePoint = cv::Point2d(reference);
  return createShapeModel(image, inPlace);
}

// A region of a textured photograph trained in place: near the region's border a level's
// gradients come from the photograph around it, as in the pyramid of a scene that shows the part,
// so each point's direction is the one a search of that image finds there, on every level.
// Trained from the region cut out, the points near its border read a reflected copy instead.
TEST(ShapeModel, ARegionIsTrainedOnThePyramidOfItsImage) {
  const cv::Mat photo = testing::testPhoto("baboon.png");  // fur: texture everywhere
  ASSERT_FALSE(photo.empty());
  // Corners and reference point on multiples of 32: whole pixels on every level.
  const cv::Rect region(192, 160, 160, 128);
  const cv::Point reference(192 + 96, 160 + 64);
  const ShapeModel model = trainedInPlace(photo, region, reference);
  ASSERT_GE(model.numLevels(), 3);
  const LevelAgreement trained = agreementWithImagePyramid(photo, model, region, reference);
  EXPECT_EQ(trained.outside, 0);
  for (const double dot : trained.leastDot) EXPECT_GT(dot, 0.9999);

  ShapeModelParams cutOut;
  cutOut.referencePoint = cv::Point2d(reference - region.tl());
  const ShapeModel cutModel = createShapeModel(photo(region).clone(), cutOut);
  const LevelAgreement cut = agreementWithImagePyramid(photo, cutModel, region, reference);
  EXPECT_EQ(cut.outside, 0);
  EXPECT_LT(*std::min_element(cut.leastDot.begin(), cut.leastDot.end()), 0.99)
      << "the cut-out region's reflected border does not show: the test sees no difference";
}

// Regions on or near the image's edges, where the image is reflected as the search image's pyramid
// reflects it: trained without error, level 0 exactly as the image's own gradients.
TEST(ShapeModel, ARegionAtTheImagesEdgeIsTrainedInPlace) {
  const cv::Mat photo = testing::testPhoto("baboon.png");  // fur: texture everywhere
  ASSERT_FALSE(photo.empty());
  for (const cv::Rect region : {cv::Rect(0, 0, 160, 128), cv::Rect(5, 3, 160, 128),
                                cv::Rect(photo.cols - 160, photo.rows - 128, 160, 128),
                                cv::Rect(37, photo.rows - 131, 150, 131)}) {
    SCOPED_TRACE(::testing::Message() << "region " << region);
    const cv::Point reference(region.x + 64, region.y + 64);
    const ShapeModel model = trainedInPlace(photo, region, reference);
    EXPECT_GE(model.numLevels(), 3);
    const LevelAgreement trained = agreementWithImagePyramid(photo, model, region, reference);
    EXPECT_GT(trained.leastDot.front(), 0.9999);
  }
}

}  // namespace
}  // namespace facet
