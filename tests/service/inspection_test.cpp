// RecipeInspection on generated parts: alignment by shape, a hole measured relative to it,
// a distance between two holes; checks, verdicts and failure causes.
#include <filesystem>

#include <gtest/gtest.h>

#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "service/daemon/inspection.hpp"
#include "tests/support/scene/parts.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;
constexpr double kMmPerPixel = 0.05;

config::Check check(std::string name, config::Quantity q, double nominal, double tol,
                    config::Unit unit) {
  config::Check c;
  c.name = std::move(name);
  c.quantity = q;
  c.nominal = nominal;
  c.tolMinus = tol;
  c.tolPlus = tol;
  c.unit = unit;
  return c;
}

class InspectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet-inspection-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    scene::SceneSpec spec;
    spec.background = 40;
    const cv::Mat templ = scene::templateScene(scene::bracketPart(), spec, 200).render();
    saveShapeModel(createShapeModel(templ), dir_ / "bracket.model");

    auto recipe = std::make_shared<config::Recipe>();
    recipe->id = 7;
    recipe->name = "bracket";
    config::Step align;
    align.id = "align";
    align.kind = config::StepKind::Align;
    config::AlignStep a;
    a.method = config::AlignStep::Method::Shape;
    a.model = dir_ / "bracket.model";
    a.minScore = 0.6;
    align.params = a;
    align.checks.push_back(check("score", config::Quantity::Score, 1.0, 0.4, config::Unit::None));
    recipe->steps.push_back(align);
    // Holes of the bracket in template pixels: the part sits at (79.5, 64.5).
    for (auto [id, centre, diameterPx] :
         {std::tuple{"big_hole", cv::Point2d(37.5, 36.5), 20.0},
          std::tuple{"small_hole", cv::Point2d(117.5, 37.5), 14.0}}) {
      config::Step s;
      s.id = id;
      s.kind = config::StepKind::Circle;
      config::CircleStep c;
      c.relativeTo = "align";
      c.centre = centre;
      c.nominalDiameter = diameterPx * kMmPerPixel;
      c.searchWidth = 4 * kMmPerPixel;
      c.polarity = config::CirclePolarity::DarkInside;
      s.params = c;
      s.checks.push_back(check("diameter", config::Quantity::Length, c.nominalDiameter, 0.01,
                               config::Unit::Millimetre));
      recipe->steps.push_back(s);
    }
    config::Step d;
    d.id = "pitch";
    d.kind = config::StepKind::Distance;
    d.params = config::DistanceStep{config::DistanceStep::Measure::CentreToCentre, "big_hole",
                                    "small_hole"};
    d.checks.push_back(check("distance", config::Quantity::Length, 80.006 * kMmPerPixel, 0.01,
                             config::Unit::Millimetre));
    recipe->steps.push_back(d);
    inspection_ = std::make_unique<RecipeInspection>(recipe, kMmPerPixel);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The bracket at a pose, optionally with its big hole resized or filled.
  static cv::Mat part(const Pose2D& pose, double bigHoleRadius) {
    scene::SceneSpec spec;
    spec.size = {640, 480};
    spec.background = 40;
    spec.blurSigma = 0.8;
    spec.noiseSigma = 2;
    scene::Scene scene(spec);
    scene::PartDrawing bracket = scene::bracketPart();
    bracket.primitives[1].radius = bigHoleRadius;
    scene::placePart(scene, bracket, pose, 200, 40);
    return scene.render();
  }

  const Measurement& value(const InspectionOutcome& out, const std::string& name) {
    for (const auto& m : out.measurements)
      if (m.name == name) return m;
    throw std::runtime_error("no measurement " + name);
  }

  fs::path dir_;
  std::unique_ptr<RecipeInspection> inspection_;
};

TEST_F(InspectionTest, GoodPartPassesWithValuesInMillimetres) {
  const auto out = inspection_->inspect({part({320.3, 240.7, radians(37), 1.0}, 10), {}});
  ASSERT_EQ(out.verdict, Verdict::Pass)
      << (out.failedChecks.empty() ? out.error : out.failedChecks[0]);
  EXPECT_NEAR(value(out, "big_hole.diameter").value, 1.0, 0.005);
  EXPECT_NEAR(value(out, "small_hole.diameter").value, 0.7, 0.005);
  EXPECT_NEAR(value(out, "pitch.distance").value, 80.006 * kMmPerPixel, 0.005);
  EXPECT_EQ(value(out, "big_hole.diameter").unit, "mm");
  ASSERT_EQ(out.timings.size(), 4u);
  EXPECT_FALSE(out.overlay.shapes.empty());
}

TEST_F(InspectionTest, OversizedHoleFailsThatCheckOnly) {
  const auto out = inspection_->inspect({part({300, 250, radians(-120), 1.0}, 10.6), {}});
  EXPECT_EQ(out.verdict, Verdict::Fail);
  EXPECT_FALSE(value(out, "big_hole.diameter").pass);
  EXPECT_NEAR(value(out, "big_hole.diameter").value, 1.06, 0.01);
  EXPECT_TRUE(value(out, "small_hole.diameter").pass);
  EXPECT_EQ(out.failedChecks, std::vector<std::string>{"big_hole.diameter"});
}

TEST_F(InspectionTest, MissingHoleFailsItsStepAndTheDistanceThatNeedsIt) {
  const auto out = inspection_->inspect({part({320, 240, 0.3, 1.0}, 0.0), {}});
  EXPECT_EQ(out.verdict, Verdict::Fail);
  EXPECT_TRUE(std::isnan(value(out, "big_hole.diameter").value));
  ASSERT_GE(out.failedChecks.size(), 2u);
  EXPECT_NE(out.failedChecks[0].find("big_hole: circle not measured"), std::string::npos)
      << out.failedChecks[0];
  EXPECT_NE(out.failedChecks[1].find("pitch: depends on failed step 'big_hole'"), std::string::npos)
      << out.failedChecks[1];
}

TEST_F(InspectionTest, NoPartFailsTheAlignment) {
  scene::SceneSpec spec;
  spec.noiseSigma = 2;
  const auto out = inspection_->inspect({scene::Scene(spec).render(), {}});
  EXPECT_EQ(out.verdict, Verdict::Fail);
  ASSERT_FALSE(out.failedChecks.empty());
  EXPECT_NE(out.failedChecks[0].find("align: part not found"), std::string::npos);
}

TEST_F(InspectionTest, EmptyImageIsAnErrorNeverAPass) {
  const auto out = inspection_->inspect({cv::Mat(), {}});
  EXPECT_EQ(out.verdict, Verdict::Error);
  EXPECT_NE(out.error.find("empty image"), std::string::npos);
}

TEST(RecipeInspectionSetup, MissingModelNamesTheFile) {
  auto recipe = std::make_shared<config::Recipe>();
  recipe->file = "/recipes/x.recipe.yaml";
  config::Step s;
  s.id = "find";
  s.kind = config::StepKind::Shape;
  config::ShapeStep shape;
  shape.model = "/nonexistent/part.model";
  s.params = shape;
  recipe->steps.push_back(s);
  try {
    RecipeInspection inspection(recipe, 0.1);
    FAIL() << "expected InspectionSetupError";
  } catch (const InspectionSetupError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/part.model"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace facet::service
