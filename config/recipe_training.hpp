#pragma once
// `facet recipe train`: every step whose kind has a model (shape models of `align` with method
// shape and of `shape`) trains it from its template image, writes it where the recipe says, and
// records beside it what it was trained from (training_record.hpp), so that a model gone stale
// is noticed when the recipe is loaded. Registration references and reference scans are used as
// they are and need no training.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/recipe.hpp"

namespace facet::config {

// Bad template (no edges, unreadable) or unwritable model file; what() names the step and file.
struct TrainingError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Trains every model of `recipe` (load it with requireTrainedModels = false). Throws
// TrainingError on the first model that cannot be trained; models trained before stay written.
std::vector<TrainedModel> trainRecipe(const Recipe& recipe);

}  // namespace facet::config
