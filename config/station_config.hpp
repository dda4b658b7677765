#pragma once
// The station config: one YAML file per station that says where frames come from, how the PLC
// is reached, where recipes, results and archived images live, and how pixels become
// millimetres. loadStationConfig() validates it completely and reports every problem with its
// file, line and column; the camera and PLC parts are the camera and PLC modules' own structs.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"

#include "camera/camera_settings.hpp"
#include "config/diagnostic.hpp"
#include "config/fleet_settings.hpp"
#include "config/recipe_loader.hpp"
#include "plc/plc_settings.hpp"
#include "plc/register_map.hpp"

namespace facet::config {

struct ResultsStoreSettings {
  std::filesystem::path database;  // SQLite file, absolute
  double keepDays = 0.0;           // parts older than this many days are deleted; 0 = keep all
  std::int64_t keepParts = 0;      // at most this many newest parts are kept; 0 = all
};

struct ArchiveSettings {
  enum class Keep { All, Failed, None };
  std::filesystem::path folder;  // absolute; empty = no archive
  double quotaMb = 0.0;          // largest size of the folder, MB
  Keep keep = Keep::Failed;
};

struct HttpSettings {
  std::string bind = "127.0.0.1";
  int port = 8080;    // 0 = any free port
  std::string token;  // empty = write actions of the dashboard are disabled
};

struct Calibration {
  double mmPerPixel = 0.0;                    // millimetres per pixel in the part's plane, > 0
  std::optional<std::filesystem::path> file;  // calibration file (config/calibration_file.hpp)
  cv::Mat cameraMatrix;                       // 3x3 CV_64F; empty without a lens model
  cv::Mat distortion;  // 1xN CV_64F (N = 4, 5, 8, 12 or 14); empty without a lens model
  cv::Size imageSize;  // the frames the lens model was made for; empty when the file has none
  std::optional<PlanePose> plane;  // the measuring plane, when the file has one

  // "lens model + plane", "lens model, scale only" or "scale only, no lens model".
  [[nodiscard]] std::string kind() const;
  // Image <-> plane mm, when there is a lens model and a plane.
  [[nodiscard]] std::optional<WorldMapping> worldMapping() const;
};

struct StationConfig {
  int schemaVersion = 1;
  std::string name;
  std::filesystem::path file;  // the station file, absolute
  CameraSettings camera;
  bool hasPlc = false;  // the file has a plc section (else: no PLC link, as with --no-plc)
  plc::PlcSettings plc;
  plc::RegisterMap registerMap;
  plc::WordOrder wordOrder = plc::WordOrder::ABCD;  // default for recipe outputs
  std::filesystem::path recipesFolder;              // absolute
  ResultsStoreSettings results;
  ArchiveSettings archive;
  HttpSettings http;
  Calibration calibration;
  MqttSettings mqtt;          // enabled when the file has an mqtt section
  PostgresSettings postgres;  // enabled when the file has a postgres section

  // Holding registers of the register map, which recipe outputs must not overlap.
  [[nodiscard]] std::vector<RegisterUse> reservedRegisters() const;
  // How recipes of this station are loaded: confined to its recipes folder, its registers
  // reserved, its word order the default.
  [[nodiscard]] RecipeLoadOptions recipeLoadOptions() const;
  // The register map while `recipe` is active: the station's map with the recipe's check
  // outputs added to its results (named "<step id>.<check>").
  [[nodiscard]] plc::RegisterMap registerMapFor(const Recipe& recipe) const;
};

struct StationLoadResult {
  std::optional<StationConfig> station;  // set exactly when diagnostics has no error
  Diagnostics diagnostics;
};

StationLoadResult loadStationConfig(const std::filesystem::path& file);

}  // namespace facet::config
