#pragma once
// A rendered test part for the measuring steps: a light plate (x 200..440, y 150..330) on a dark
// background with a bore (centre (260, 200), radius 8) and three slots 6 px wide at x 297, 317,
// 337 (y 260..300); blur 0.8 px, noise 1 grey level. And a recipe of given steps, loaded with the
// built-in kinds and prepared at 0.05 mm per pixel.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "config/recipe_loader.hpp"
#include "service/engine/builtin_steps.hpp"
#include "service/engine/inspect_part.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet::service::plate {

namespace fs = std::filesystem;
constexpr double kMmPerPixel = 0.05;

inline const config::StepKindRegistry& kinds() {
  static const config::StepKindRegistry registry = builtinSteps();
  return registry;
}

inline cv::Mat render(bool withBore = true) {
  scene::SceneSpec spec;
  spec.background = 40;
  spec.blurSigma = 0.8;
  spec.noiseSigma = 1;
  scene::Scene s(spec);
  s.addPolygon({{200, 150}, {440, 150}, {440, 330}, {200, 330}}, 200);
  if (withBore) s.addDisc({260, 200}, 8, 40, "hole");
  for (double x : {297.0, 317.0, 337.0})
    s.addPolygon({{x, 260}, {x + 6, 260}, {x + 6, 300}, {x, 300}}, 40, "hole");
  return s.render();
}

// Writes "<dir>/plate.recipe.yaml" with `steps` (YAML, indented by two) and loads it.
inline config::RecipeLoadResult load(const fs::path& dir, const std::string& steps) {
  fs::create_directories(dir);
  std::ofstream(dir / "plate.recipe.yaml") << "schema_version: 1\nid: 9\nname: plate\nsteps:\n"
                                           << steps;
  return config::loadRecipe(dir / "plate.recipe.yaml", kinds());
}

// Scale only: 0.05 mm per pixel.
inline config::Calibration scaleOnly() {
  config::Calibration calibration;
  calibration.mmPerPixel = kMmPerPixel;
  return calibration;
}

// A lens model without distortion looking straight at a plane 120 mm away: 0.05 mm per pixel
// in the plane, so that the plane's millimetres can be checked against the scale's.
inline config::Calibration straightPlane() {
  config::Calibration calibration = scaleOnly();
  calibration.cameraMatrix = (cv::Mat_<double>(3, 3) << 2400, 0, 319.5, 0, 2400, 239.5, 0, 0, 1);
  calibration.imageSize = {640, 480};
  calibration.plane = PlanePose{.translationMm = {0, 0, 120}};
  return calibration;
}

inline InspectionOutcome inspect(const fs::path& dir, const std::string& steps,
                                 const cv::Mat& image,
                                 const config::Calibration& calibration = scaleOnly()) {
  const auto loaded = load(dir, steps);
  if (!loaded.recipe) throw std::runtime_error(loaded.diagnostics.text());
  const auto recipe =
      prepareRecipe(std::make_shared<const config::Recipe>(*loaded.recipe), calibration);
  return inspectPart({image, std::nullopt}, *recipe);
}

inline const Measurement& value(const InspectionOutcome& out, const std::string& name) {
  for (const auto& m : out.measurements)
    if (m.name == name) return m;
  throw std::runtime_error("no measurement " + name);
}

inline std::string failures(const InspectionOutcome& out) {
  std::string all = out.error;
  for (const auto& f : out.failedChecks) all += f + "; ";
  return all;
}

}  // namespace facet::service::plate
