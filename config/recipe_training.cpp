#include "config/recipe_training.hpp"

namespace facet::config {

std::vector<TrainedModel> trainRecipe(const Recipe& recipe) {
  std::vector<TrainedModel> trained;
  for (const auto& step : recipe.steps) {
    auto models = step.kind->train(step);
    trained.insert(trained.end(), models.begin(), models.end());
  }
  return trained;
}

}  // namespace facet::config
