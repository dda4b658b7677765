// facet recipe check | train | schema: validating, training and describing recipe files.
#include <fstream>
#include <iostream>
#include <map>

#include "config/json_schema.hpp"
#include "config/recipe_library.hpp"
#include "config/recipe_loader.hpp"
#include "config/recipe_training.hpp"
#include "config/station_config.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

using config::Diagnostic;
using config::Diagnostics;

struct Options {
  std::vector<std::string> files;
  std::string station;
  std::string root;
  bool json = false;
};

nlohmann::json toJson(const Diagnostic& d) {
  return {{"file", d.where.file.string()},
          {"line", d.where.line},
          {"column", d.where.column},
          {"severity", d.severity == config::Severity::Error ? "error" : "warning"},
          {"message", d.message}};
}

// The station (when given) decides the recipes folder, reserved registers and word order.
config::RecipeLoadOptions loadOptions(const Options& opt, Diagnostics& out,
                                      std::optional<config::StationConfig>& station) {
  config::RecipeLoadOptions options;
  if (!opt.station.empty()) {
    auto loaded = config::loadStationConfig(opt.station);
    out.append(loaded.diagnostics);
    if (loaded.station) {
      options = loaded.station->recipeLoadOptions();
      station = std::move(loaded.station);
    }
  }
  if (!opt.root.empty()) options.root = opt.root;
  return options;
}

// FILE arguments: recipe files, or folders searched for *.recipe.yaml; none = the station's
// recipes folder.
std::vector<std::filesystem::path> recipeFiles(
    const Options& opt, const std::optional<config::StationConfig>& station) {
  std::vector<std::filesystem::path> files;
  std::vector<std::filesystem::path> args(opt.files.begin(), opt.files.end());
  if (args.empty() && station) args.push_back(station->recipesFolder);
  for (const auto& arg : args) {
    if (!std::filesystem::is_directory(arg)) {
      files.push_back(arg);
      continue;
    }
    std::vector<std::filesystem::path> found;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(arg)) {
      const std::string name = entry.path().filename().string();
      if (entry.is_regular_file() && name.ends_with(config::kRecipeFileSuffix))
        found.push_back(entry.path());
    }
    std::sort(found.begin(), found.end());
    for (const auto& f : found) files.push_back(std::filesystem::proximate(f));
  }
  return files;
}

void check(const Options& opt, const config::StepKindRegistry& kinds) {
  Diagnostics all;
  std::optional<config::StationConfig> station;
  const auto options = loadOptions(opt, all, station);
  if (!opt.json) {
    std::cerr << all.text();  // the station file's problems
    if (station) std::cout << opt.station << ": ok\n";
  }
  const auto files = recipeFiles(opt, station);
  if (files.empty() && opt.station.empty())
    throw InputError("recipe check: give recipe files, folders or --station");

  nlohmann::json results = nlohmann::json::array();
  std::map<int, std::filesystem::path> ids;  // recipe ids are unique across the files checked
  for (const auto& file : files) {
    auto loaded = config::loadRecipe(file, kinds, options);
    if (loaded.id > 0) {
      const auto [it, first] = ids.emplace(loaded.id, file);
      if (!first) {
        loaded.diagnostics.error(loaded.idWhere, "recipe id " + std::to_string(loaded.id) +
                                                     " is already used by " + it->second.string());
        loaded.recipe.reset();
      }
    }
    const bool ok = !loaded.diagnostics.hasErrors();
    nlohmann::json r{{"file", file.string()}, {"ok", ok}};
    if (ok && loaded.recipe) {
      r["id"] = loaded.recipe->id;
      r["name"] = loaded.recipe->name;
      r["steps"] = loaded.recipe->steps.size();
      r["hash"] = loaded.recipe->contentHash;
    }
    r["diagnostics"] = nlohmann::json::array();
    for (const auto& d : loaded.diagnostics.items()) r["diagnostics"].push_back(toJson(d));
    results.push_back(r);
    all.append(loaded.diagnostics);
    if (!opt.json) {
      std::cerr << loaded.diagnostics.text();
      if (ok && loaded.recipe)
        std::cout << file.string() << ": ok (recipe " << loaded.recipe->id << " '"
                  << loaded.recipe->name << "', " << loaded.recipe->steps.size() << " steps)\n";
    }
  }
  const std::size_t errors = all.errorCount();
  const std::size_t warnings = all.items().size() - errors;
  if (opt.json) {
    nlohmann::json stationJson = nullptr;
    if (!opt.station.empty()) {
      stationJson = {{"file", opt.station}, {"ok", station.has_value()}};
    }
    printJson({{"ok", errors == 0},
               {"errors", errors},
               {"warnings", warnings},
               {"station", stationJson},
               {"recipes", results},
               {"diagnostics", [&] {
                  auto list = nlohmann::json::array();
                  for (const auto& d : all.items()) list.push_back(toJson(d));
                  return list;
                }()}});
  }
  if (errors > 0)
    throw InputError(std::to_string(errors) + " error(s) in " + std::to_string(files.size()) +
                     " recipe file(s)" + (opt.station.empty() ? "" : " and the station file"));
}

void train(const Options& opt, const config::StepKindRegistry& kinds) {
  Diagnostics all;
  std::optional<config::StationConfig> station;
  auto options = loadOptions(opt, all, station);
  options.requireTrainedModels = false;
  if (all.hasErrors()) throw InputError("the station file has errors:\n" + all.text());
  nlohmann::json trainedJson = nlohmann::json::array();
  for (const auto& file : recipeFiles(opt, station)) {
    const auto loaded = config::loadRecipe(file, kinds, options);
    if (!loaded.recipe)
      throw InputError(file.string() + " has errors; nothing trained:\n" +
                       loaded.diagnostics.text());
    try {
      for (const auto& t : config::trainRecipe(*loaded.recipe)) {
        trainedJson.push_back({{"recipe", file.string()},
                               {"step", t.stepId},
                               {"model", t.model.string()},
                               {"levels", t.numLevels},
                               {"points", t.points}});
        if (!opt.json)
          std::cout << file.string() << ": step '" << t.stepId << "': trained " << t.model.string()
                    << " (" << t.numLevels << " levels, " << t.points << " points)\n";
      }
    } catch (const config::TrainingError& e) {
      throw MeasurementFailure("training_failed", file.string() + ": " + e.what());
    }
  }
  if (opt.json) printJson({{"trained", trainedJson}});
}

}  // namespace

void addRecipeCommand(CLI::App& app, const config::StepKindRegistry& kinds) {
  auto* recipe = app.add_subcommand("recipe", "Check, train and describe recipe files");
  recipe->require_subcommand(1);

  auto opt = std::make_shared<Options>();
  auto* checkCmd = recipe->add_subcommand(
      "check", "Validate recipe files and report every problem as file:line:column: message");
  checkCmd->add_option("files", opt->files, "Recipe files or folders of *.recipe.yaml files");
  checkCmd->add_option("--station", opt->station,
                       "Station file: its recipes folder, registers and word order apply; "
                       "without FILE every recipe of the station is checked");
  checkCmd->add_option("--root", opt->root,
                       "Recipes folder paths must stay inside (default: the recipe's folder)");
  checkCmd->add_flag("--json", opt->json, "Print one JSON object");
  checkCmd->callback([opt, &kinds] { check(*opt, kinds); });

  auto* trainCmd = recipe->add_subcommand(
      "train", "Create the shape models a recipe needs, with a record of what they came from");
  trainCmd->add_option("files", opt->files, "Recipe files or folders")->required();
  trainCmd->add_option("--station", opt->station, "Station file");
  trainCmd->add_option("--root", opt->root, "Recipes folder");
  trainCmd->add_flag("--json", opt->json, "Print one JSON object");
  trainCmd->callback([opt, &kinds] { train(*opt, kinds); });

  auto kind = std::make_shared<std::string>("recipe");
  auto output = std::make_shared<std::string>();
  auto* schemaCmd = recipe->add_subcommand(
      "schema", "Print the JSON schema of recipe or station files (for editors)");
  schemaCmd->add_option("kind", *kind, "recipe or station")
      ->check(CLI::IsMember({"recipe", "station"}));
  schemaCmd->add_option("--output,-o", *output, "Write to this file instead of stdout");
  schemaCmd->callback([kind, output, &kinds] {
    const auto schema =
        *kind == "station" ? config::stationJsonSchema() : config::recipeJsonSchema(kinds);
    if (output->empty()) {
      std::cout << schema.dump(2) << "\n";
      return;
    }
    std::ofstream out(*output);
    out << schema.dump(2) << "\n";
    if (!out) throw InputError(*output + ": cannot write");
  });
}

}  // namespace facet::cli
