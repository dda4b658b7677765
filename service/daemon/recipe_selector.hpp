#pragma once
// RecipeSelector: which recipe inspects the next part. It owns the recipe library and the
// prepared recipes (one per id, prepared again only when the library reloads that recipe),
// decides once per part, and switches only between parts.
//
// The choice, in order: the recipe a recorded frame names in its sidecar (replay regression),
// the PLC's recipe select at the trigger, a switch asked over HTTP, the recipe in use. A recipe
// that cannot be used (unknown id, resources broken) is refused, counted and logged, and the
// recipe in use stays. Thread-safe.

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "camera/camera.hpp"
#include "config/recipe_library.hpp"
#include "config/station_config.hpp"
#include "plc/plc_link.hpp"
#include "service/daemon/metrics.hpp"
#include "service/engine/inspect_part.hpp"

namespace facet::service {

class RecipeSelector {
 public:
  using Recipe = std::shared_ptr<const PreparedRecipe>;

  // Loads the recipes folder and prepares the first recipe (`first`, default: the lowest id).
  // Throws std::runtime_error when there is no usable recipe, naming the problems.
  RecipeSelector(const config::StationConfig& station, const config::StepKindRegistry& kinds,
                 std::optional<int> first, MetricsRegistry& metrics);

  // The recipe for the part about to be taken: decided here, once per part. A switch calls
  // the switch observer (the PLC's active-recipe register).
  Recipe choose(const Frame* frame, const plc::TriggerEvent* trigger);
  // What choose() would give for a trigger without a frame, without choosing or switching (the
  // acquisition asks it whether the part is a range scan or an image).
  [[nodiscard]] Recipe peek(const plc::TriggerEvent* trigger);
  [[nodiscard]] Recipe active() const;

  // A switch asked over HTTP, applied to the next part. False for an unknown recipe.
  bool request(int recipeId);
  // Re-reads the recipes folder; a broken recipe is rejected and the one in use stays.
  config::ReloadReport reload();
  [[nodiscard]] bool changedOnDisk() const { return library_.changedOnDisk(); }
  [[nodiscard]] std::vector<std::shared_ptr<const config::Recipe>> recipes() const {
    return library_.recipes();
  }
  // Recipe files rejected and recipes whose resources failed, for /healthz and the dashboard.
  [[nodiscard]] nlohmann::json problems() const;

  void onSwitch(std::function<void(int recipeId)> observer) { onSwitch_ = std::move(observer); }

 private:
  // The prepared recipe of an id, from the cache or prepared now (caller holds mutex_).
  Recipe preparedLocked(int recipeId, std::string& error);
  [[nodiscard]] std::optional<int> wantedLocked(const Frame* frame,
                                                const plc::TriggerEvent* trigger) const;

  config::Calibration calibration_;
  MetricsRegistry& metrics_;
  config::RecipeLibrary library_;
  mutable std::mutex mutex_;
  std::map<int, Recipe> prepared_;     // by recipe id
  std::map<int, std::string> errors_;  // preparation errors by id
  Recipe active_;
  std::optional<int> requested_;  // from HTTP, applied before the next part
  std::function<void(int)> onSwitch_;
};

}  // namespace facet::service
