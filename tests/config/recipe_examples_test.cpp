// The shipped examples: every example recipe passes validation against the example station,
// the shipped JSON schemas equal the generated ones, and the demo folders hold what the daemon
// and the integration tests expect (640x480 8-bit images with sidecars naming the verdict).
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "config/json_schema.hpp"
#include "config/recipe_library.hpp"
#include "config/station_config.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config {
namespace {

using test::facetSteps;

const std::filesystem::path kRecipes = std::filesystem::path(FACET_SOURCE_DIR) / "recipes";

nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

TEST(Examples, EveryExampleRecipeIsValidAndEveryStepKindIsCovered) {
  const auto station = loadStationConfig(kRecipes / "station.yaml");
  ASSERT_TRUE(station.station.has_value()) << station.diagnostics.text();
  RecipeLibrary library(facetSteps(), station.station->recipeLoadOptions());
  const auto report = library.reload();
  EXPECT_TRUE(report.diagnostics.empty()) << report.diagnostics.text();
  EXPECT_TRUE(report.rejected.empty());
  std::set<std::string_view> kinds;
  for (const auto& recipe : library.recipes())
    for (const auto& step : recipe->steps) kinds.insert(step.kindName());
  EXPECT_EQ(kinds.size(), facetSteps().kinds().size()) << "some step kind has no example";
  EXPECT_EQ(library.recipes().size(), 4u);
}

TEST(Examples, RecipeOutputsJoinTheStationRegisterMapWithoutCollisions) {
  const auto station = loadStationConfig(kRecipes / "station.yaml");
  ASSERT_TRUE(station.station.has_value()) << station.diagnostics.text();
  const auto recipe = loadRecipe(kRecipes / "bracket_registration.recipe.yaml", facetSteps(),
                                 station.station->recipeLoadOptions());
  ASSERT_TRUE(recipe.recipe.has_value()) << recipe.diagnostics.text();
  const plc::RegisterMap map = station.station->registerMapFor(*recipe.recipe);
  EXPECT_TRUE(map.validate().empty());
  const plc::ResultOutput* spacing = map.findResult("bore_spacing.distance");
  ASSERT_NE(spacing, nullptr);
  EXPECT_EQ(spacing->address, 104);
  EXPECT_EQ(spacing->type, plc::ValueType::ScaledInt32);
  EXPECT_DOUBLE_EQ(spacing->factor, 1000.0);
  EXPECT_EQ(spacing->wordOrder, plc::WordOrder::ABCD);
  // The origin names the file and the line of the output's `plc:` entry.
  std::ifstream file(kRecipes / "bracket_registration.recipe.yaml");
  int line = 0, plcLine = 0;
  for (std::string text; std::getline(file, text) && plcLine == 0;)
    if (++line; text.find("plc: {register: 104") != std::string::npos) plcLine = line;
  ASSERT_GT(plcLine, 0);
  EXPECT_NE(
      spacing->origin.find("bracket_registration.recipe.yaml:" + std::to_string(plcLine) + ":"),
      std::string::npos)
      << spacing->origin;
  // The measuring tools' outputs follow the bores'.
  for (const auto& [name, address] : {std::pair<std::string, int>{"leg_width.width", 106},
                                      {"top_edge.straightness", 108},
                                      {"corner_bore.presence", 109}}) {
    const plc::ResultOutput* out = map.findResult(name);
    ASSERT_NE(out, nullptr) << name;
    EXPECT_EQ(out->address, address) << name;
  }
}

TEST(Examples, ShippedSchemasEqualTheGeneratedOnes) {
  EXPECT_EQ(readJson(kRecipes / "recipe.schema.json"), recipeJsonSchema(facetSteps()))
      << "regenerate with: facet recipe schema -o recipes/recipe.schema.json";
  EXPECT_EQ(readJson(kRecipes / "station.schema.json"), stationJsonSchema())
      << "regenerate with: facet recipe schema station -o recipes/station.schema.json";
}

TEST(Examples, SchemaDescribesEveryStepKindAndRefusesUnknownKeys) {
  const auto schema = recipeJsonSchema(facetSteps());
  const auto& kinds = schema["properties"]["steps"]["items"]["oneOf"];
  ASSERT_EQ(kinds.size(), facetSteps().kinds().size());
  for (const auto& kind : kinds) {
    EXPECT_FALSE(kind["additionalProperties"].get<bool>());
    EXPECT_TRUE(kind["properties"].contains("id"));
    EXPECT_TRUE(kind["properties"]["kind"].contains("const"));
  }
  EXPECT_EQ(schema["properties"]["id"]["maximum"], 65535.0);
}

TEST(Examples, DemoFoldersHoldImagesWithVerdictSidecars) {
  for (const std::string name : {"bracket_registration", "bracket_shape", "fiducial_board"}) {
    std::set<std::string> verdicts, serials;
    int images = 0;
    for (const auto& entry : std::filesystem::directory_iterator(kRecipes / "demo" / name)) {
      if (entry.path().extension() != ".png") continue;
      ++images;
      const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
      EXPECT_EQ(image.size(), cv::Size(640, 480)) << entry.path();
      EXPECT_EQ(image.type(), CV_8UC1) << entry.path();
      const auto sidecar = readJson(entry.path().string() + ".json");
      const auto& a = sidecar["annotations"];
      verdicts.insert(a["expected_verdict"].get<std::string>());
      serials.insert(a["serial"].get<std::string>());
    }
    EXPECT_GE(images, 10) << name;
    EXPECT_EQ(serials.size(), static_cast<std::size_t>(images)) << name;
    EXPECT_EQ(verdicts, (std::set<std::string>{"fail", "pass"})) << name;
  }
  int scans = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kRecipes / "demo/scan_offset")) {
    if (entry.path().extension() != ".csv") continue;
    ++scans;
    const auto sidecar = readJson(entry.path().string() + ".json");
    EXPECT_TRUE(sidecar.contains("serial"));
    EXPECT_TRUE(sidecar["expected_verdict"] == "pass" || sidecar["expected_verdict"] == "fail");
  }
  EXPECT_GE(scans, 10);
}

}  // namespace
}  // namespace facet::config
