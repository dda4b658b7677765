#pragma once
// What `facet replay --shard/--results` and `facet validate` share: a recipe loaded and
// prepared the way `facet replay` does it (calibration and recipe root from --station, or
// --mm-per-pixel), ready to inspect recorded parts one by one.

#include <memory>
#include <string>

#include "config/step_kind.hpp"
#include "service/engine/inspect_part.hpp"

namespace facet::cli {

// Throws InputError naming the file when the station, the recipe or its resources are bad.
std::shared_ptr<const service::PreparedRecipe> loadRecipeForBatch(
    const std::string& recipeFile, const std::string& stationFile, double mmPerPixel,
    const config::StepKindRegistry& kinds);

}  // namespace facet::cli
