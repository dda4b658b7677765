// The inspection engine on generated parts, through a recipe file as the line writes it:
// alignment by shape, holes measured relative to it, a distance between two holes; checks,
// verdicts and failure causes. What prepareRecipe() refuses, and the warm-up before a first part.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "config/recipe_format.hpp"
#include "config/recipe_loader.hpp"
#include "service/engine/builtin_steps.hpp"
#include "service/engine/inspect_part.hpp"
#include "service/engine/warm_up.hpp"
#include "tests/support/scene/parts.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;
constexpr double kMmPerPixel = 0.05;

const config::StepKindRegistry& kinds() {
  static const config::StepKindRegistry registry = builtinSteps();
  return registry;
}

class InspectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet-inspection-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    scene::SceneSpec spec;
    spec.background = 40;
    const cv::Mat templ = scene::templateScene(scene::bracketPart(), spec, 200).render();
    cv::imwrite((dir_ / "bracket.png").string(), templ);
    saveShapeModel(createShapeModel(templ), dir_ / "bracket.model");
    // Holes of the bracket in template pixels: the part sits at (79.5, 64.5); 20 and 14 px.
    std::ofstream(dir_ / "bracket.recipe.yaml") << R"(schema_version: 1
id: 7
name: bracket
steps:
  - id: align
    kind: align
    method: shape
    reference: bracket.png
    model: bracket.model
    min_score: 0.6
    checks:
      score: {nominal: 1.0, tol_minus: 0.4, tol_plus: 0.4}
  - id: big_hole
    kind: circle
    relative_to: align
    centre: [37.5, 36.5]
    nominal_diameter: 1.0
    search_width: 0.2
    polarity: dark_inside
    checks:
      diameter: {nominal: 1.0, tol_minus: 0.01, tol_plus: 0.01}
  - id: small_hole
    kind: circle
    relative_to: align
    centre: [117.5, 37.5]
    nominal_diameter: 0.7
    search_width: 0.2
    polarity: dark_inside
    checks:
      diameter: {nominal: 0.7, tol_minus: 0.01, tol_plus: 0.01}
  - id: pitch
    kind: distance
    measure: centre_to_centre
    from: big_hole
    to: small_hole
    checks:
      distance: {nominal: 4.0003, tol_minus: 0.01, tol_plus: 0.01}
)";
    recipe_ = loadPrepared("bracket.recipe.yaml");
    ASSERT_TRUE(recipe_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A recipe file of dir_, loaded and prepared with the test's calibration; null (and the
  // loader's diagnostics as a failure) when it does not load.
  [[nodiscard]] std::shared_ptr<const PreparedRecipe> loadPrepared(const std::string& file) const {
    const auto loaded = config::loadRecipe(dir_ / file, kinds());
    EXPECT_TRUE(loaded.recipe) << loaded.diagnostics.text();
    if (!loaded.recipe) return nullptr;
    config::Calibration calibration;
    calibration.mmPerPixel = kMmPerPixel;
    return prepareRecipe(std::make_shared<const config::Recipe>(*loaded.recipe), calibration);
  }

  [[nodiscard]] InspectionOutcome inspect(const cv::Mat& image) const {
    return inspectPart({image, std::nullopt}, *recipe_);
  }

  // The bracket at a pose, optionally with its big hole resized or filled, or its small hole
  // moved along the part's x.
  static cv::Mat part(const Pose2D& pose, double bigHoleRadius, double smallHoleShift = 0.0) {
    scene::SceneSpec spec;
    spec.size = {640, 480};
    spec.background = 40;
    spec.blurSigma = 0.8;
    spec.noiseSigma = 2;
    scene::Scene scene(spec);
    scene::PartDrawing bracket = scene::bracketPart();
    bracket.primitives[1].radius = bigHoleRadius;
    bracket.primitives[2].centre.x += smallHoleShift;
    scene::placePart(scene, bracket, pose, 200, 40);
    return scene.render();
  }

  const Measurement& value(const InspectionOutcome& out, const std::string& name) {
    for (const auto& m : out.measurements)
      if (m.name == name) return m;
    throw std::runtime_error("no measurement " + name);
  }

  fs::path dir_;
  std::shared_ptr<const PreparedRecipe> recipe_;
};

TEST_F(InspectionTest, GoodPartPassesWithValuesInMillimetres) {
  const auto out = inspect(part({320.3, 240.7, radians(37), 1.0}, 10));
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
  const auto out = inspect(part({300, 250, radians(-120), 1.0}, 10.6));
  EXPECT_EQ(out.verdict, Verdict::Fail);
  EXPECT_FALSE(value(out, "big_hole.diameter").pass);
  EXPECT_NEAR(value(out, "big_hole.diameter").value, 1.06, 0.01);
  EXPECT_TRUE(value(out, "small_hole.diameter").pass);
  EXPECT_EQ(out.failedChecks, std::vector<std::string>{"big_hole.diameter"});
}

TEST_F(InspectionTest, HoleOffItsPlaceIsMeasuredWhereItIsAndFailsItsPosition) {
  // The small hole 8 px = 0.4 mm off, outside its annulus.
  const auto out = inspect(part({300, 250, 0.0, 1.0}, 10.0, 8.0));
  EXPECT_EQ(out.verdict, Verdict::Fail);
  EXPECT_NEAR(value(out, "small_hole.diameter").value, 0.7, 0.01);
  EXPECT_TRUE(value(out, "small_hole.diameter").pass);
  // The pitch grows by the offset: the defect is measured, not just reported as a failed step.
  EXPECT_NEAR(value(out, "pitch.distance").value, 4.0003 + 0.4, 0.01);
  EXPECT_EQ(out.failedChecks, std::vector<std::string>{"pitch.distance"});
}

TEST_F(InspectionTest, MissingHoleFailsItsStepAndTheDistanceThatNeedsIt) {
  const auto out = inspect(part({320, 240, 0.3, 1.0}, 0.0));
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
  const auto out = inspect(scene::Scene(spec).render());
  EXPECT_EQ(out.verdict, Verdict::Fail);
  ASSERT_FALSE(out.failedChecks.empty());
  EXPECT_NE(out.failedChecks[0].find("align: part not found"), std::string::npos);
}

TEST_F(InspectionTest, EmptyImageIsAnErrorNeverAPass) {
  const auto out = inspect(cv::Mat());
  EXPECT_EQ(out.verdict, Verdict::Error);
  EXPECT_NE(out.error.find("empty image"), std::string::npos);
}

// The warm-up inspects the align step's reference picture, bordered: the taught part, so every
// step finds what it measures, relative steps included (the template is drawn without blur, so
// a check may still fail). A recipe without a picture gets none.
TEST_F(InspectionTest, WarmUpInspectsTheReferencePictureWithEveryStep) {
  const auto out = warmUp(*recipe_);
  ASSERT_TRUE(out.has_value());
  ASSERT_NE(out->verdict, Verdict::Error) << out->error;
  for (const auto& failed : out->failedChecks)
    EXPECT_EQ(failed.find(": "), std::string::npos) << "a step failed: " << failed;
  EXPECT_EQ(out->timings.size(), 4u);
  EXPECT_NEAR(value(*out, "big_hole.diameter").value, 1.0, 0.03);
  EXPECT_NEAR(value(*out, "small_hole.diameter").value, 0.7, 0.03);

  PreparedRecipe none;
  none.loaded = std::make_shared<const config::Recipe>();
  EXPECT_FALSE(warmUp(none).has_value());
}

// A recipe that only counts parts by shape warms up on the shape step's template.
TEST_F(InspectionTest, WarmUpOfAShapeOnlyRecipeFindsThePartInItsTemplate) {
  std::ofstream(dir_ / "count.recipe.yaml") << R"(schema_version: 1
id: 8
name: count
steps:
  - id: brackets
    kind: shape
    template: bracket.png
    model: bracket.model
    min_score: 0.7
    num_matches: 10
    checks:
      count: {nominal: 4, tol_minus: 0, tol_plus: 0}
)";
  const auto recipe = loadPrepared("count.recipe.yaml");
  ASSERT_TRUE(recipe);
  const auto out = warmUp(*recipe);
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(value(*out, "brackets.count").value, 1.0);  // one in the picture: the check fails
  EXPECT_EQ(out->verdict, Verdict::Fail);
}

TEST_F(InspectionTest, MissingModelIsReportedWhenTheRecipeIsLoaded) {
  fs::remove(dir_ / "bracket.model");
  const auto loaded = config::loadRecipe(dir_ / "bracket.recipe.yaml", kinds());
  EXPECT_FALSE(loaded.recipe);
  EXPECT_NE(loaded.diagnostics.text().find("model 'bracket.model' does not exist"),
            std::string::npos)
      << loaded.diagnostics.text();
}

// A kind the reader knows but no unit runs (a registry made for checking files only).
class ReadOnlyKind : public config::StepKind {
 public:
  ReadOnlyKind() : format_(config::stepFormat("note", "A remark.", {}, checks_)) {}
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override { return {}; }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading&) const override {
    return std::make_shared<config::StepParams>();
  }

 private:
  config::ObjectSpec checks_{"note checks", "", {}};
  config::StepKindSpec format_;
};

TEST(PrepareRecipe, RefusesAStepNoUnitRuns) {
  config::StepKindRegistry readOnly;
  readOnly.add(std::make_unique<ReadOnlyKind>());
  const fs::path file = fs::temp_directory_path() / "facet-note.recipe.yaml";
  std::ofstream(file)
      << "schema_version: 1\nid: 1\nname: n\nsteps:\n  - id: hello\n    kind: note\n";
  const auto loaded = config::loadRecipe(file, readOnly);
  fs::remove(file);
  ASSERT_TRUE(loaded.recipe) << loaded.diagnostics.text();
  config::Calibration calibration;
  calibration.mmPerPixel = 0.1;
  try {
    (void)prepareRecipe(std::make_shared<const config::Recipe>(*loaded.recipe), calibration);
    FAIL() << "expected InspectionSetupError";
  } catch (const InspectionSetupError& e) {
    EXPECT_NE(std::string(e.what()).find("step 'hello' of kind 'note' cannot run"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace facet::service
