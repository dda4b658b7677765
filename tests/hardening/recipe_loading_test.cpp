// loadRecipe reports problems as diagnostics and never throws, whatever the YAML holds. First
// found by the recipe fuzz target: reading a key that a mapping does not have (a PLC output without
// `factor`, a step without `kind`) threw yaml-cpp's InvalidNode out of loadRecipe, so the
// example recipes themselves could not be loaded.

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config/recipe_loader.hpp"
#include "service/engine/builtin_steps.hpp"

namespace facet::config {
namespace {

namespace fs = std::filesystem;

class RecipeLoading : public ::testing::Test {
 protected:
  RecipeLoading() {
    std::random_device rd;
    folder_ = fs::temp_directory_path() / ("facet_recipe_loading_" + std::to_string(rd()));
    fs::create_directories(folder_);
  }
  ~RecipeLoading() override {
    std::error_code ec;
    fs::remove_all(folder_, ec);
  }
  RecipeLoadResult load(const std::string& text) const {
    const fs::path file = folder_ / "part.recipe.yaml";
    std::ofstream(file) << text;
    return loadRecipe(file, kinds_);
  }

  fs::path folder_;
  const StepKindRegistry kinds_ = service::builtinSteps();
};

constexpr const char* kHead = R"(schema_version: 1
id: 3
name: Plate
steps:
  - id: marks
    kind: fiducials
    marks: [[170, 115], [470, 115], [170, 365]]
    mark_diameter: 0.8
    search_radius: 2.5
    checks:
)";

TEST_F(RecipeLoading, PlcOutputWithoutFactorLoads) {
  RecipeLoadResult r;
  ASSERT_NO_THROW(r = load(std::string(kHead) +
                           "      angle: {nominal: 0, tol_minus: 5, tol_plus: 5, "
                           "plc: {register: 120, type: float32}}\n"));
  ASSERT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
  const Check* angle = r.recipe->steps.at(0).check("angle");
  ASSERT_NE(angle, nullptr);
  ASSERT_TRUE(angle->plc.has_value());
  EXPECT_EQ(angle->plc->output.address, 120);
  EXPECT_EQ(angle->plc->output.type, plc::ValueType::Float32);
}

TEST_F(RecipeLoading, ScaledOutputWithoutFactorIsAnErrorNotAnException) {
  RecipeLoadResult r;
  ASSERT_NO_THROW(r = load(std::string(kHead) +
                           "      angle: {nominal: 0, tol_minus: 5, tol_plus: 5, "
                           "plc: {register: 120, type: scaled_int16}}\n"));
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_NE(r.diagnostics.text().find("needs a 'factor'"), std::string::npos)
      << r.diagnostics.text();
}

TEST_F(RecipeLoading, MissingKeysEverywhereGiveDiagnosticsNotExceptions) {
  const std::vector<std::string> texts = {
      std::string("schema_version: 1\nid: 1\nname: x\nsteps:\n  - id: a\n"),
      "schema_version: 1\nid: 1\nname: x\nsteps:\n  - kind: circle\n",
      "schema_version: 1\nid: 1\nname: x\nsteps:\n  - id: a\n    kind: bogus\n",
      std::string(kHead) + "      angle: {plc: {}}\n",
      std::string(kHead) + "      angle: {plc: {type: int16}}\n",
      "steps: [{id: d, kind: distance, checks: {distance: {plc: {register: 1}}}}]\n",
  };
  for (const auto& text : texts) {
    RecipeLoadResult r;
    ASSERT_NO_THROW(r = load(text)) << text;
    EXPECT_FALSE(r.recipe.has_value()) << text;
    EXPECT_TRUE(r.diagnostics.hasErrors()) << text;
  }
}

// Found by the recipe fuzz target: std::filesystem::is_regular_file threw "File name too long"
// out of loadRecipe (and out of loadStationConfig for a calibration file).
TEST_F(RecipeLoading, FileNameTooLongIsReportedNotThrown) {
  const std::string name = std::string(300, 'n') + ".png";
  RecipeLoadResult r;
  ASSERT_NO_THROW(r = load("schema_version: 1\nid: 1\nname: x\nsteps:\n  - id: part\n"
                           "    kind: align\n    method: registration\n    reference: " +
                           name + "\n"));
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_NE(r.diagnostics.text().find("does not exist"), std::string::npos) << r.diagnostics.text();
}

}  // namespace
}  // namespace facet::config
