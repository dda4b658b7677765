#pragma once
// What `facet replay --shard/--results` and `facet validate` share: a recipe loaded and
// prepared the way `facet replay` does it (calibration and recipe root from --station, or
// --mm-per-pixel), ready to inspect recorded parts one by one.

#include <memory>
#include <string>

#include "config/recipe.hpp"
#include "service/daemon/inspection.hpp"

namespace facet::cli {

struct PreparedRecipe {
  std::shared_ptr<const config::Recipe> recipe;
  std::unique_ptr<service::RecipeInspection> inspection;
  double mmPerPixel = 0;
};

// Throws InputError naming the file when the station, the recipe or its resources are bad.
PreparedRecipe prepareRecipe(const std::string& recipeFile, const std::string& stationFile,
                             double mmPerPixel);

}  // namespace facet::cli
