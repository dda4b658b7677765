// Recipe validation: every kind of problem is reported with its exact line and column, all of
// them in one run, and a recipe with an error is never returned.
#include <fstream>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "config/recipe_loader.hpp"
#include "config/recipe_training.hpp"
#include "config/training_record.hpp"
#include "service/engine/steps/circle_step.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config::test {
namespace {

// Lines 1-8 of every recipe below: a registration align step named `part` on ref.png.
const std::string kHead = R"(schema_version: 1
id: 7
name: Test
steps:
  - id: part
    kind: align
    method: registration
    reference: ref.png
)";

class RecipeValidation : public testing::Test {
 protected:
  void SetUp() override { scratch.writeImage("ref.png"); }

  RecipeLoadResult load(const std::string& text, RecipeLoadOptions options = {}) {
    const auto file = scratch.write("test.recipe.yaml", text);
    if (!options.root) options.root = scratch.path();
    return loadRecipe(file, facetSteps(), options);
  }

  ScratchFolder scratch;
};

TEST_F(RecipeValidation, AValidRecipeLoadsWithItsStepsAndChecks) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    relative_to: part
    centre: [30, 20]
    nominal_diameter: 1.0
    search_width: 0.3
    polarity: dark_inside
    checks:
      diameter: {nominal: 1.0, tol_minus: 0.03, tol_plus: 0.05, plc: {register: 100, type: float32}}
      x: {nominal: 0, tol_minus: 0.1, tol_plus: 0.1}
)");
  ASSERT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
  EXPECT_TRUE(r.diagnostics.empty()) << r.diagnostics.text();
  const Recipe& recipe = *r.recipe;
  EXPECT_EQ(recipe.id, 7);
  ASSERT_EQ(recipe.steps.size(), 2u);
  EXPECT_EQ(recipe.steps[0].kindName(), "align");
  const Step& hole = recipe.steps[1];
  const auto& circle = hole.as<service::CircleParams>();
  EXPECT_EQ(circle.relativeTo, "part");
  EXPECT_EQ(circle.centre, cv::Point2d(30, 20));
  EXPECT_EQ(circle.polarity, facet::CirclePolarity::DarkToLight);
  const Check* diameter = hole.check("diameter");
  ASSERT_NE(diameter, nullptr);
  EXPECT_DOUBLE_EQ(diameter->lower(), 0.97);
  EXPECT_DOUBLE_EQ(diameter->upper(), 1.05);
  EXPECT_TRUE(diameter->passes(1.04));
  EXPECT_FALSE(diameter->passes(0.96));
  ASSERT_TRUE(diameter->plc.has_value());
  EXPECT_EQ(diameter->plc->output.name, "hole.diameter");
  EXPECT_EQ(diameter->plc->output.address, 100);
  EXPECT_EQ(diameter->plc->words(), 2);
  EXPECT_EQ(diameter->plc->where.line, 17);
  EXPECT_EQ(hole.check("x")->unit, Unit::Millimetre);
  // The reference image is a dependency the library watches.
  EXPECT_EQ(recipe.dependencies.size(), 1u);
  EXPECT_EQ(recipe.contentHash.size(), 16u);
}

TEST_F(RecipeValidation, UnknownKeySuggestsTheClosestValidKey) {
  const auto r = load(kHead + "    min_scor: 0.5\n");
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 9, 5,
                            "unknown key 'min_scor' in align step (did you mean 'min_score'?)"));
}

TEST_F(RecipeValidation, UnknownKeyFarFromEveryKeyListsTheValidKeys) {
  const auto r = load("colour: red\n" + kHead);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 1, 1, "unknown key 'colour' in recipe (valid keys: "));
}

TEST_F(RecipeValidation, WrongTypeNamesKeyAndValue) {
  const auto r = load(kHead + "    min_score: high\n");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 9, 16, "'min_score' must be a number, not \"high\""));
}

TEST_F(RecipeValidation, QuotedNumberIsTextNotANumber) {
  const auto r = load("schema_version: 1\nid: \"7\"\nname: x\nsteps: []\n");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 2, 5, "'id' must be a whole number, not \"7\""));
}

TEST_F(RecipeValidation, OutOfRangeValuesGiveTheRange) {
  const auto r = load(
      "schema_version: 2\nid: 70000\nname: x\nsteps:\n  - id: part\n"
      "    kind: align\n    method: registration\n    reference: ref.png\n"
      "    min_score: 1.5\n    angle_range: [30, -30]\n");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 1, 17, "'schema_version' must be 1 (got 2)"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 2, 5, "'id' must be between 1 and 65535 (got 70000)"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 9, 16, "'min_score' must be at most 1 (got 1.5)"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 10, 18, "must have low <= high (got [30, -30])"));
  EXPECT_EQ(r.diagnostics.errorCount(), 4u) << r.diagnostics.text();
}

TEST_F(RecipeValidation, ShapeSearchTolerancesAreLimited) {
  for (const auto& [key, value, message] :
       {std::tuple{"scale_tolerance", "0.5",
                   "'scale_tolerance' must be between 0 and 0.1 (got 0.5)"},
        std::tuple{"max_deformation", "9", "'max_deformation' must be between 0 and 8 (got 9)"}}) {
    const auto r = load(std::string("schema_version: 1\nid: 7\nname: x\nsteps:\n  - id: part\n"
                                    "    kind: shape\n    template: t.png\n    ") +
                        key + ": " + value + "\n");
    // The value's column: after four spaces, the key and ": ".
    EXPECT_TRUE(
        hasDiagnostic(r.diagnostics, 8, 7 + static_cast<int>(std::string(key).size()), message))
        << r.diagnostics.text();
  }
}

TEST_F(RecipeValidation, MissingRequiredKeyIsReportedAtItsMapping) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    nominal_diameter: 1.0
    search_width: 0.3
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 9, 5, "circle step is missing required key 'centre'"));
}

TEST_F(RecipeValidation, UnknownStepKindSuggestsOne) {
  const auto r = load(kHead + "  - id: hole\n    kind: circel\n");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 10, 11,
                            "unknown step kind 'circel' (did you mean 'circle'?); expected one of "
                            "align, fiducials, shape, circle, caliper, line, blob, distance, "
                            "scan_align"));
}

TEST_F(RecipeValidation, UnknownEnumNameSuggestsOne) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
    polarity: dark_insid
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 14, 15,
                            "unknown polarity 'dark_insid' (did you mean 'dark_inside'?)"));
}

TEST_F(RecipeValidation, DuplicateKeyIsAnError) {
  const auto r = load("schema_version: 1\nid: 7\nid: 8\nname: x\nsteps: []\n");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 3, 1, "duplicate key 'id' (first given at line 2)"));
}

TEST_F(RecipeValidation, YamlSyntaxErrorHasItsPosition) {
  const auto r = load("schema_version: 1\nid: [7, 8\nname: x\n");
  ASSERT_EQ(r.diagnostics.items().size(), 1u);
  EXPECT_GT(r.diagnostics.items()[0].where.line, 0);
  EXPECT_NE(r.diagnostics.items()[0].message.find("not valid YAML"), std::string::npos);
}

TEST_F(RecipeValidation, MissingFileIsReportedWithWhereItWasLookedFor) {
  std::string text = kHead;
  text.replace(text.find("ref.png"), 7, "nope.png");
  const auto r = load(text);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "'reference' file 'nope.png' does not exist"));
}

// The reference scan of a scan_align step is read by the inspection's own scan parser: a row it
// would refuse is reported (with the scan file's line) at the recipe's 'reference', and a file it
// reads is accepted.
TEST_F(RecipeValidation, ReferenceScanIsCheckedByTheInspectionsParser) {
  const std::string recipe = R"(schema_version: 1
id: 4
name: Scan
steps:
  - id: fixture
    kind: scan_align
    reference: corner.csv
)";
  scratch.write("corner.csv", "x,y\n1.0,0.0\n1.0,0.5\n0.5,1.0\n");
  const auto good = load(recipe);
  EXPECT_TRUE(good.recipe.has_value()) << good.diagnostics.text();

  scratch.write("corner.csv", "x,y\n1.0,0.0\n1.0,0.5,7\n0.5,1.0\n");
  const auto bad = load(recipe);
  EXPECT_FALSE(bad.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(bad.diagnostics, 7, 16,
                            "corner.csv:3: expected 2 comma-separated values, got 3"))
      << bad.diagnostics.text();

  scratch.write("corner.csv", "x,y\n1.0,0.0\n1.0,0.5\n");
  EXPECT_TRUE(hasDiagnostic(load(recipe).diagnostics, 7, 16, "has 2 points; at least 3"));
}

TEST_F(RecipeValidation, PathWithDotDotLeavingTheFolderIsRefused) {
  const ScratchFolder outside;
  outside.writeImage("secret.png");
  std::string text = kHead;
  const std::string escape =
      std::filesystem::relative(outside.path() / "secret.png", scratch.path()).string();
  ASSERT_TRUE(escape.starts_with(".."));
  text.replace(text.find("ref.png"), 7, escape);
  const auto r = load(text);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "leaves the recipes folder"));
}

TEST_F(RecipeValidation, DotDotThatStaysInsideTheFolderIsFine) {
  scratch.writeImage("models/ref.png");
  std::string text = kHead;
  text.replace(text.find("ref.png"), 7, "models/../models/ref.png");
  const auto r = load(text);
  EXPECT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
}

TEST_F(RecipeValidation, AbsolutePathIsRefused) {
  std::string text = kHead;
  text.replace(text.find("ref.png"), 7, (scratch.path() / "ref.png").string());
  const auto r = load(text);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "is absolute"));
}

TEST_F(RecipeValidation, SymbolicLinkPointingOutOfTheFolderIsRefused) {
  const ScratchFolder outside;
  outside.writeImage("secret.png");
  std::filesystem::create_symlink(outside.path() / "secret.png", scratch.path() / "link.png");
  std::filesystem::create_directory_symlink(outside.path(), scratch.path() / "linkdir");
  for (const std::string name : {"link.png", "linkdir/secret.png"}) {
    std::string text = kHead;
    text.replace(text.find("ref.png"), 7, name);
    const auto r = load(text);
    EXPECT_FALSE(r.recipe.has_value());
    EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "through a symbolic link")) << name;
  }
}

TEST_F(RecipeValidation, DuplicateStepIdNamesTheFirst) {
  const auto r = load(kHead +
                      "  - id: part\n    kind: align\n    method: registration\n"
                      "    reference: ref.png\n");
  EXPECT_TRUE(
      hasDiagnostic(r.diagnostics, 9, 9, "duplicate step id 'part' (first used at line 5)"));
}

TEST_F(RecipeValidation, ReferenceToUnknownStepSuggestsOne) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    relative_to: prat
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 11, 18,
                            "'relative_to' refers to unknown step 'prat' (did you mean 'part'?)"));
}

TEST_F(RecipeValidation, ReferenceToALaterStepIsRefused) {
  const auto r = load(kHead + R"(  - id: spacing
    kind: distance
    measure: centre_to_centre
    from: part
    to: hole
  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 13, 9,
                            "'to' refers to step 'hole', which comes later (line 14); a step may "
                            "only use earlier steps"));
}

TEST_F(RecipeValidation, ReferenceToAStepOfTheWrongKindIsRefused) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
  - id: other
    kind: circle
    relative_to: hole
    centre: [5, 2]
    nominal_diameter: 1.0
    search_width: 0.3
  - id: gap
    kind: distance
    measure: point_to_line
    from: part
    to: hole
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 16, 18,
                            "'relative_to' needs a step that gives a pose (align, fiducials or "
                            "shape), but 'hole' is a circle step"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 24, 9, "'to' needs a step that gives a line"));
}

TEST_F(RecipeValidation, TolMinusLargerThanANonNegativeNominalIsRefused) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
    checks:
      diameter:
        nominal: 1.0
        tol_minus: 1.2
        tol_plus: 0.03
      x:
        nominal: 0
        tol_minus: 0.5
        tol_plus: 0.5
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 17, 20,
                            "tol_minus 1.2 of 'hole.diameter' is larger than its nominal 1 "
                            "allows: the lower limit -0.2 is below 0"));
  // An offset may go below zero: x with tol_minus > nominal is fine.
  EXPECT_EQ(r.diagnostics.errorCount(), 1u) << r.diagnostics.text();
}

TEST_F(RecipeValidation, NegativeToleranceAndWrongUnitAreRefused) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
    checks:
      diameter:
        nominal: 1.0
        tol_minus: 0.1
        tol_plus: -0.1
        unit: deg
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 18, 19, "'tol_plus' must be at least 0 (got -0.1)"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 19, 15,
                            "'hole.diameter' is a length: its unit is mm or px, not deg"));
}

TEST_F(RecipeValidation, SearchWidthMustBeSmallerThanTheDiameter) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 1.5
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 13, 19, "'search_width' 1.5 mm must be smaller than"));
}

TEST_F(RecipeValidation, CollidingPlcRegistersAreRefused) {
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
    checks:
      diameter:
        nominal: 1.0
        tol_minus: 0.1
        tol_plus: 0.1
        plc: {register: 100, type: float32}
      x:
        nominal: 0
        tol_minus: 0.1
        tol_plus: 0.1
        plc: {register: 101, type: int16}
      y:
        nominal: 0
        tol_minus: 0.1
        tol_plus: 0.1
        plc: {register: 102, type: scaled_int16}
)");
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 24, 25,
                            "register 101 of 'hole.x' collides with 'hole.diameter' (registers "
                            "100-101, line 19)"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 29, 36, "type scaled_int16 needs a 'factor'"));
  EXPECT_EQ(r.diagnostics.errorCount(), 2u) << r.diagnostics.text();
}

TEST_F(RecipeValidation, RegistersReservedByTheStationAreRefused) {
  RecipeLoadOptions options;
  options.reservedRegisters.push_back(
      {"station status.heartbeat", 101, 1, {"station.yaml", 40, 7}});
  const auto r = load(kHead + R"(  - id: hole
    kind: circle
    centre: [1, 2]
    nominal_diameter: 1.0
    search_width: 0.3
    checks:
      diameter: {nominal: 1.0, tol_minus: 0.1, tol_plus: 0.1, plc: {register: 100, type: int32}}
)",
                      options);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 15, 79,
                            "register 100-101 of 'hole.diameter' collides with 'station "
                            "status.heartbeat' (registers 101, station.yaml:40)"));
}

TEST_F(RecipeValidation, EveryProblemIsReportedInOneRun) {
  const auto r = load(R"(schema_version: 1
id: 0
name: Test
steps:
  - id: part
    kind: align
    method: registration
    reference: nope.png
    min_scor: 0.5
  - id: hole
    kind: circle
    relative_to: nowhere
    centre: [1, 2]
    nominal_diameter: -1
    search_width: 0.3
)");
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 2, 5, "'id' must be between 1 and 65535"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "does not exist"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 9, 5, "unknown key 'min_scor'"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 12, 18, "unknown step 'nowhere'"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 14, 23, "'nominal_diameter' must be greater than 0"));
  EXPECT_EQ(r.diagnostics.errorCount(), 5u) << r.diagnostics.text();
  // Each message is printed as file:line:column: message.
  EXPECT_NE(r.diagnostics.text().find("test.recipe.yaml:9:5: unknown key 'min_scor'"),
            std::string::npos);
}

// A shape step's model must exist and match what it was trained from.
TEST_F(RecipeValidation, ShapeModelsMustBeTrainedAndFresh) {
  scratch.writeImage("label.png", 96, 64);
  const std::string text = kHead + R"(  - id: label
    kind: shape
    relative_to: part
    template: label.png
    model: models/label.shape
    angle_range: [-30, 30]
)";
  auto r = load(text);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 13, 12,
                            "model 'models/label.shape' does not exist; run `facet recipe train"));

  RecipeLoadOptions training;
  training.requireTrainedModels = false;
  r = load(text, training);
  ASSERT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
  const auto trained = trainRecipe(*r.recipe);
  ASSERT_EQ(trained.size(), 1u);
  EXPECT_GT(trained[0].points, 8u);
  r = load(text);
  ASSERT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
  // The training record holds the parameters as canonical text.
  const std::string params = "shape;region=all;angle=-30,30";
  std::ifstream record(scratch.path() / "models/label.shape.train.json");
  EXPECT_EQ(nlohmann::json::parse(record).value("parameters", ""), params);

  // Other training parameters in the recipe: stale.
  std::string changed = text;
  changed.replace(changed.find("[-30, 30]"), 9, "[-40, 40]");
  r = load(changed);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 13, 12, "is stale: was trained with other parameters"));

  // A model file that the shape module cannot read (another format version, corrupt), even
  // with a matching training record.
  const auto model = scratch.path() / "models/label.shape";
  const auto saved = scratch.path() / "label.shape.saved";
  std::filesystem::copy_file(model, saved);
  scratch.write("models/label.shape", "FACETSHM but not really a model");
  writeTrainingRecord(model, scratch.path() / "label.png", params);
  r = load(text);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 13, 12, "model 'models/label.shape' cannot be loaded"));
  std::filesystem::copy_file(saved, model, std::filesystem::copy_options::overwrite_existing);
  writeTrainingRecord(model, scratch.path() / "label.png", params);

  // A new template image: stale.
  scratch.writeImage("label.png", 90, 64);
  r = load(text);
  EXPECT_TRUE(
      hasDiagnostic(r.diagnostics, 13, 12, "is stale: was trained from a different label.png"));
}

}  // namespace
}  // namespace facet::config::test
