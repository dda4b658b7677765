#include "service/cli/batch_inspection.hpp"

#include "config/recipe_loader.hpp"
#include "config/station_config.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

std::shared_ptr<const service::PreparedRecipe> loadRecipeForBatch(
    const std::string& recipeFile, const std::string& stationFile, double mmPerPixel,
    const config::StepKindRegistry& kinds) {
  config::RecipeLoadOptions loadOptions;
  config::Calibration calibration;
  if (!stationFile.empty()) {
    const auto station = config::loadStationConfig(stationFile);
    if (!station.station)
      throw InputError(station.diagnostics.text() + stationFile + ": station config has errors");
    loadOptions = station.station->recipeLoadOptions();
    calibration = station.station->calibration;
  }
  if (mmPerPixel > 0) calibration.mmPerPixel = mmPerPixel;
  if (calibration.mmPerPixel <= 0)
    throw InputError("give --station (for its calibration) or --mm-per-pixel > 0");
  const auto loaded = config::loadRecipe(recipeFile, kinds, loadOptions);
  if (!loaded.recipe)
    throw InputError(loaded.diagnostics.text() + recipeFile + ": recipe has errors");
  try {
    return service::prepareRecipe(std::make_shared<const config::Recipe>(*loaded.recipe),
                                  calibration);
  } catch (const service::InspectionSetupError& e) {
    throw InputError(recipeFile + ": " + e.what());
  }
}

}  // namespace facet::cli
