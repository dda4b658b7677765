#pragma once
// StepReading: what a step kind sees of the recipe while its step is read and prepared: the
// step's YAML mapping, the place of every key for messages, the steps before it (for references
// such as `relative_to`) and the recipes folder its files must stay inside.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "config/diagnostic.hpp"
#include "config/step_kind.hpp"

namespace facet::config {

struct RecipeLoadOptions;

class StepReading {
 public:
  // An earlier step of the recipe, as far as references to it need to know.
  struct EarlierStep {
    const StepKind* kind = nullptr;
    SourceLocation where;
  };

  StepReading(const YAML::Node& step, const std::filesystem::path& file,
              const std::filesystem::path& baseFolder, const std::filesystem::path& root,
              const RecipeLoadOptions& options, const StepKindRegistry& kinds,
              const std::map<std::string, EarlierStep>& earlier,
              const std::map<std::string, int>& allIds, Diagnostics& out);

  // The step's mapping; `in["key"]` is the value of one key (undefined when absent).
  [[nodiscard]] const YAML::Node& node() const { return step_; }
  [[nodiscard]] YAML::Node operator[](const std::string& key) const { return step_[key]; }
  [[nodiscard]] const RecipeLoadOptions& options() const { return options_; }
  [[nodiscard]] const std::filesystem::path& recipeFile() const { return file_; }

  [[nodiscard]] SourceLocation where(const YAML::Node& n) const;
  void error(const YAML::Node& at, std::string message);
  void warning(const YAML::Node& at, std::string message);
  [[nodiscard]] bool hasErrors() const { return errors_ > 0; }

  // The id of an earlier step named by `key` whose result offers `wanted` (a pose, a point, a
  // line); it becomes an input of this step. Reports a later, unknown or unfit step. Empty when
  // the key is absent or not a name.
  std::optional<std::string> stepRef(const std::string& key, bool StepOffers::*wanted);

  // The file named by `key`, resolved against the recipe's folder and confined to the recipes
  // folder; it becomes a dependency of the recipe (a change to it reloads the recipe). Reports a
  // path that leaves the folder, and, unless `mayBeMissing`, a file that does not exist.
  std::optional<std::filesystem::path> path(const std::string& key, bool mayBeMissing = false);

  // What the reading found besides the kind's parameters (read by the loader).
  [[nodiscard]] const std::vector<std::string>& inputs() const { return inputs_; }
  [[nodiscard]] const std::vector<std::filesystem::path>& dependencies() const {
    return dependencies_;
  }
  // A file the step depends on without naming it (a model's training record).
  void addDependency(std::filesystem::path file) { dependencies_.push_back(std::move(file)); }

 private:
  YAML::Node step_;
  const std::filesystem::path& file_;
  const std::filesystem::path& baseFolder_;
  const std::filesystem::path& root_;
  const RecipeLoadOptions& options_;
  const StepKindRegistry& kinds_;
  const std::map<std::string, EarlierStep>& earlier_;
  const std::map<std::string, int>& allIds_;
  Diagnostics& out_;
  int errors_ = 0;
  std::vector<std::string> inputs_;
  std::vector<std::filesystem::path> dependencies_;
};

}  // namespace facet::config
