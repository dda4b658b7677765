#include "service/daemon/recipe_selector.hpp"

#include <chrono>

#include <spdlog/spdlog.h>

namespace facet::service {
namespace {

// The recipe a recorded frame names in its sidecar, if any.
std::optional<int> sidecarRecipe(const Frame& frame) {
  const auto it = frame.metadata.find("recipe");
  if (it == frame.metadata.end()) return std::nullopt;
  try {
    return std::stoi(it->second);
  } catch (const std::exception&) {
    spdlog::warn("{}: sidecar recipe '{}' is not a number", frame.source, it->second);
    return std::nullopt;
  }
}

}  // namespace

RecipeSelector::RecipeSelector(const config::StationConfig& station,
                               const config::StepKindRegistry& kinds, std::optional<int> first,
                               MetricsRegistry& metrics)
    : calibration_(station.calibration),
      metrics_(metrics),
      library_(kinds, station.recipeLoadOptions()) {
  const auto report = library_.reload();
  for (const auto& d : report.diagnostics.items()) spdlog::error("recipe: {}", config::format(d));
  const auto recipes = library_.recipes();
  if (recipes.empty())
    throw std::runtime_error("no usable recipe in " + station.recipesFolder.string() +
                             (report.diagnostics.empty() ? "" : ":\n" + report.diagnostics.text()));
  const int id = first.value_or(recipes.front()->id);
  std::lock_guard lock(mutex_);
  std::string error;
  active_ = preparedLocked(id, error);
  if (!active_) throw std::runtime_error("recipe " + std::to_string(id) + ": " + error);
}

RecipeSelector::Recipe RecipeSelector::preparedLocked(int recipeId, std::string& error) {
  const auto recipe = library_.find(recipeId);
  if (!recipe) {
    error = "no such recipe";
    return nullptr;
  }
  auto& cached = prepared_[recipeId];
  if (cached && cached->loaded == recipe) return cached;
  try {
    cached = prepareRecipe(recipe, calibration_);
    errors_.erase(recipeId);
    return cached;
  } catch (const std::exception& e) {
    error = e.what();
    errors_[recipeId] = e.what();
    spdlog::error("recipe {}: {}", recipeId, e.what());
    // A recipe whose preparation broke keeps running in its last good one, if any.
    return cached;
  }
}

std::optional<int> RecipeSelector::wantedLocked(const Frame* frame,
                                                const plc::TriggerEvent* trigger) const {
  if (frame)
    if (auto id = sidecarRecipe(*frame)) return id;
  if (trigger && trigger->recipe > 0) return trigger->recipe;
  return requested_;
}

RecipeSelector::Recipe RecipeSelector::peek(const plc::TriggerEvent* trigger) {
  std::lock_guard lock(mutex_);
  const auto wanted = wantedLocked(nullptr, trigger);
  if (!wanted) return active_;
  std::string error;  // reported by choose(), which falls back the same way
  const Recipe recipe = preparedLocked(*wanted, error);
  return recipe ? recipe : active_;
}

RecipeSelector::Recipe RecipeSelector::choose(const Frame* frame,
                                              const plc::TriggerEvent* trigger) {
  const auto t0 = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  // Without a wish, the recipe in use: picks up a reloaded version of it, if any.
  const int wanted = wantedLocked(frame, trigger).value_or(active_->recipe().id);
  requested_.reset();
  std::string error;
  const Recipe next = preparedLocked(wanted, error);
  if (!next) {
    spdlog::error("recipe {} requested but not usable ({}); staying with {}", wanted, error,
                  active_->recipe().id);
    metrics_.counter("facet_recipe_switch_failures_total", "Recipe switches refused").increment();
    return active_;
  }
  if (next == active_) return active_;
  const bool switched = next->recipe().id != active_->recipe().id;
  active_ = next;
  if (switched) {
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    metrics_.counter("facet_recipe_switches_total", "Recipe switches between parts").increment();
    metrics_.gauge("facet_recipe_switch_ms", "Duration of the last recipe switch").set(ms);
    spdlog::info("recipe switched to {} '{}' in {:.2f} ms", next->recipe().id, next->recipe().name,
                 ms);
    if (onSwitch_) onSwitch_(next->recipe().id);
  }
  return active_;
}

RecipeSelector::Recipe RecipeSelector::active() const {
  std::lock_guard lock(mutex_);
  return active_;
}

bool RecipeSelector::request(int recipeId) {
  if (!library_.find(recipeId)) return false;
  std::lock_guard lock(mutex_);
  requested_ = recipeId;
  return true;
}

config::ReloadReport RecipeSelector::reload() {
  auto report = library_.reload();
  for (const auto& d : report.diagnostics.items()) spdlog::error("recipe: {}", config::format(d));
  std::lock_guard lock(mutex_);
  for (int id : report.loaded) {
    std::string error;
    if (preparedLocked(id, error)) spdlog::info("recipe {} reloaded", id);
  }
  metrics_.counter("facet_recipe_reloads_total", "Recipe folder reloads").increment();
  return report;
}

nlohmann::json RecipeSelector::problems() const {
  nlohmann::json problems = nlohmann::json::array();
  for (const auto& d : library_.problems().items()) problems.push_back(config::format(d));
  std::lock_guard lock(mutex_);
  for (const auto& [id, e] : errors_) problems.push_back("recipe " + std::to_string(id) + ": " + e);
  return problems;
}

}  // namespace facet::service
