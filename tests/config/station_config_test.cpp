// The station config: the example loads into the camera and PLC modules' own structs; problems
// are reported with line and column, the register map's through the PLC module's parser.
#include <gtest/gtest.h>

#include "config/station_config.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config::test {
namespace {

const std::filesystem::path kExample =
    std::filesystem::path(FACET_SOURCE_DIR) / "recipes/station.yaml";

TEST(StationConfig, TheExampleStationLoads) {
  const auto r = loadStationConfig(kExample);
  ASSERT_TRUE(r.station.has_value()) << r.diagnostics.text();
  EXPECT_TRUE(r.diagnostics.empty()) << r.diagnostics.text();
  const StationConfig& s = *r.station;
  EXPECT_EQ(s.camera.backend, CameraBackend::Replay);
  EXPECT_EQ(s.camera.replay.folder.filename(), "bracket_registration");
  EXPECT_TRUE(s.camera.replay.loop);
  EXPECT_EQ(s.camera.replay.trigger, TriggerMode::Software);
  EXPECT_EQ(s.camera.replay.colour, ColourConversion::Mono);
  EXPECT_EQ(s.plc.host, "127.0.0.1");
  EXPECT_EQ(s.plc.port, 1502);
  EXPECT_EQ(s.plc.mode, plc::HandshakeMode::Triggered);
  ASSERT_TRUE(s.registerMap.control.trigger.has_value());
  EXPECT_EQ(s.registerMap.control.trigger->table, plc::Table::Coil);
  ASSERT_TRUE(s.registerMap.status.heartbeat.has_value());
  EXPECT_EQ(s.registerMap.status.heartbeat->address, 11);
  EXPECT_EQ(s.recipesFolder, kExample.parent_path().lexically_normal());
  EXPECT_EQ(s.http.port, 8080);
  EXPECT_EQ(s.archive.keep, ArchiveSettings::Keep::Failed);
  EXPECT_DOUBLE_EQ(s.archive.quotaMb, 200.0);
  // The calibration file (made by facet calibrate from the example camera's plates: f = 2400 px,
  // 0.05 mm per pixel in the plane) gives intrinsics, distortion, the plane and the scale.
  EXPECT_NEAR(s.calibration.mmPerPixel, 0.05, 1e-4);
  ASSERT_EQ(s.calibration.cameraMatrix.rows, 3);
  EXPECT_NEAR(s.calibration.cameraMatrix.at<double>(0, 0), 2400.0, 5.0);
  EXPECT_EQ(s.calibration.distortion.total(), 5u);
  // Its holding registers are reserved: recipe outputs may not overlap them.
  const auto reserved = s.reservedRegisters();
  ASSERT_EQ(reserved.size(), 5u);
  EXPECT_EQ(reserved[0].owner, "station control.recipe_select");
  EXPECT_EQ(reserved[0].address, 0);
  EXPECT_EQ(reserved[0].where.file, kExample.string());
  EXPECT_EQ(reserved[0].where.line, 33);  // where the PLC module says the entry is
  EXPECT_EQ(s.recipeLoadOptions().root, s.recipesFolder);
}

class StationProblems : public testing::Test {
 protected:
  StationLoadResult load(const std::string& text) {
    return loadStationConfig(scratch.write("station.yaml", text));
  }
  ScratchFolder scratch;
};

const std::string kMinimal = R"(schema_version: 1
camera:
  backend: replay
  replay:
    folder: .
plc:
  register_map:
    control:
      trigger: {coil: 0}
recipes: .
results:
  database: results.db
calibration:
  mm_per_pixel: 0.05
)";

TEST_F(StationProblems, MinimalStationLoads) {
  const auto r = load(kMinimal);
  ASSERT_TRUE(r.station.has_value()) << r.diagnostics.text();
  EXPECT_EQ(r.station->results.database, scratch.path() / "results.db");
}

TEST_F(StationProblems, ResultsRetentionIsReadAndCheckedWithItsLine) {
  std::string text = kMinimal;
  text.replace(text.find("  database: results.db"), 22,
               "  database: results.db\n  keep_days: 1.5\n  keep_parts: 200000");
  auto r = load(text);
  ASSERT_TRUE(r.station.has_value()) << r.diagnostics.text();
  EXPECT_DOUBLE_EQ(r.station->results.keepDays, 1.5);
  EXPECT_EQ(r.station->results.keepParts, 200000);

  const auto unset = load(kMinimal);
  ASSERT_TRUE(unset.station.has_value());
  EXPECT_EQ(unset.station->results.keepDays, 0.0);  // keep everything
  EXPECT_EQ(unset.station->results.keepParts, 0);

  text.replace(text.find("keep_parts: 200000"), 18, "keep_parts: 0");
  r = load(text);
  EXPECT_FALSE(r.station.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 14, 15, "'keep_parts' must be")) << r.diagnostics.text();
}

TEST_F(StationProblems, ThePlcSectionIsOptional) {
  const auto with = load(kMinimal);
  ASSERT_TRUE(with.station.has_value()) << with.diagnostics.text();
  EXPECT_TRUE(with.station->hasPlc);
  std::string text = kMinimal;
  const auto plc = text.find("plc:\n");
  text.erase(plc, text.find("recipes:") - plc);
  const auto without = load(text);
  ASSERT_TRUE(without.station.has_value()) << without.diagnostics.text();
  EXPECT_TRUE(without.diagnostics.empty()) << without.diagnostics.text();
  EXPECT_FALSE(without.station->hasPlc);
  EXPECT_FALSE(without.station->registerMap.control.trigger.has_value());
  EXPECT_TRUE(without.station->reservedRegisters().empty());
}

TEST_F(StationProblems, UnknownKeysAndBadValuesAreReportedTogether) {
  std::string text = kMinimal;
  text.replace(text.find("  backend: replay"), 17, "  backend: replay\n  exposure: 100");
  text.replace(text.find("recipes: ."), 10, "recipes: nowhere");
  text += "http:\n  port: 99999\n";
  const auto r = load(text);
  EXPECT_FALSE(r.station.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 4, 3, "unknown key 'exposure' in camera"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 11, 10, "'recipes' folder 'nowhere' does not exist"));
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 17, 9, "'port' must be between 0 and 65535"));
}

TEST_F(StationProblems, RegisterMapTyposGetSuggestions) {
  std::string text = kMinimal;
  text.replace(text.find("trigger: {coil: 0}"), 18, "triger: {coil: 0}");
  const auto r = load(text);
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 9, 7,
                            "unknown key 'triger' in control signals (did you mean 'trigger'?)"));
}

TEST_F(StationProblems, RegisterMapCollisionsComeFromThePlcModuleWithTheirPlace) {
  std::string text = kMinimal;
  text.replace(text.find("      trigger: {coil: 0}"), 24,
               "      trigger: {coil: 0}\n      result_ack: {coil: 0}");
  const auto r = load(text);
  EXPECT_FALSE(r.station.has_value());
  ASSERT_TRUE(r.diagnostics.hasErrors());
  const std::string all = r.diagnostics.text();
  EXPECT_NE(all.find("control.trigger"), std::string::npos) << all;
  EXPECT_NE(all.find("control.result_ack"), std::string::npos) << all;
}

TEST_F(StationProblems, CalibrationNeedsAScale) {
  std::string text = kMinimal;
  text.replace(text.find("  mm_per_pixel: 0.05"), 20, "  file: missing.yaml");
  const auto r = load(text);
  EXPECT_TRUE(
      hasDiagnostic(r.diagnostics, 14, 9, "calibration file 'missing.yaml' does not exist"));
}

TEST_F(StationProblems, CalibrationFileWithoutDistortionIsRefused) {
  scratch.write("cal.yaml",
                "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n"
                "   cols: 3\n   dt: d\n   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]\n");
  std::string text = kMinimal;
  text.replace(text.find("  mm_per_pixel: 0.05"), 20, "  mm_per_pixel: 0.05\n  file: cal.yaml");
  const auto r = load(text);
  // The calibration file's own problem is reported in that file, and the station points to it.
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 15, 9, "calibration file 'cal.yaml' is not usable"));
  EXPECT_NE(r.diagnostics.text().find("cal.yaml: needs 'distortion_coefficients'"),
            std::string::npos)
      << r.diagnostics.text();
}

}  // namespace
}  // namespace facet::config::test
