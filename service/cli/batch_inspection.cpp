#include "service/cli/batch_inspection.hpp"

#include "config/recipe_loader.hpp"
#include "config/station_config.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

PreparedRecipe prepareRecipe(const std::string& recipeFile, const std::string& stationFile,
                             double mmPerPixel) {
  config::RecipeLoadOptions loadOptions;
  if (!stationFile.empty()) {
    const auto station = config::loadStationConfig(stationFile);
    if (!station.station)
      throw InputError(station.diagnostics.text() + stationFile + ": station config has errors");
    loadOptions = station.station->recipeLoadOptions();
    if (mmPerPixel <= 0) mmPerPixel = station.station->calibration.mmPerPixel;
  }
  if (mmPerPixel <= 0)
    throw InputError("give --station (for its calibration) or --mm-per-pixel > 0");
  const auto loaded = config::loadRecipe(recipeFile, loadOptions);
  if (!loaded.recipe)
    throw InputError(loaded.diagnostics.text() + recipeFile + ": recipe has errors");
  PreparedRecipe prepared;
  prepared.recipe = std::make_shared<const config::Recipe>(*loaded.recipe);
  prepared.mmPerPixel = mmPerPixel;
  try {
    prepared.inspection = std::make_unique<service::RecipeInspection>(prepared.recipe, mmPerPixel);
  } catch (const service::InspectionSetupError& e) {
    throw InputError(recipeFile + ": " + e.what());
  }
  return prepared;
}

}  // namespace facet::cli
