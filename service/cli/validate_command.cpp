// facet validate: the golden-set gate. Runs a recipe over recorded parts whose sidecars hold the
// expected verdict (and optionally expected values with tolerances), prints every mismatch as a
// table and exits with 3 when there is any (service/batch/golden_set.hpp describes the format).
#include <algorithm>
#include <iomanip>
#include <iostream>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "service/batch/batch_replay.hpp"
#include "service/batch/golden_set.hpp"
#include "service/cli/batch_inspection.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

// Exit code of a gate that found mismatches (1: bad input, 2: measurement failed).
constexpr int kMismatchExit = 3;

struct ValidateOptions {
  std::string recipeFile;
  std::string goldenFolder;
  std::string stationFile;
  double mmPerPixel = 0;
  std::string glob;
  bool json = false;
};

void printTable(const std::vector<service::GoldenMismatch>& rows) {
  const std::vector<std::string> header{"file", "serial", "check", "expected", "got"};
  std::vector<std::size_t> width;
  for (const auto& h : header) width.push_back(h.size());
  for (const auto& r : rows) {
    const std::vector<const std::string*> cells{&r.file, &r.serial, &r.check, &r.expected};
    for (std::size_t i = 0; i < cells.size(); ++i) width[i] = std::max(width[i], cells[i]->size());
  }
  auto line = [&](const std::vector<std::string>& cells) {
    for (std::size_t i = 0; i + 1 < cells.size(); ++i)
      std::cout << std::left << std::setw(static_cast<int>(width[i]) + 2) << cells[i];
    std::cout << cells.back() << "\n";
  };
  line(header);
  for (const auto& r : rows) line({r.file, r.serial, r.check, r.expected, r.got});
}

void runValidate(const ValidateOptions& opt, const config::StepKindRegistry& kinds) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("facet-validate"));
  const auto prepared = loadRecipeForBatch(opt.recipeFile, opt.stationFile, opt.mmPerPixel, kinds);
  const bool scans = service::scanRecipe(*prepared);
  std::vector<service::RecordedPart> parts;
  SidecarMetadata sidecars;
  try {
    parts = service::listShare(opt.goldenFolder, opt.glob, scans, {});
    sidecars = SidecarMetadata::loadFolder(opt.goldenFolder);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (parts.empty())
    throw InputError(opt.goldenFolder + ": no recorded " + (scans ? "scan" : "image") +
                     " to validate against");
  std::vector<service::GoldenMismatch> mismatches;
  std::size_t matching = 0;
  for (const auto& part : parts) {
    const auto result = service::inspectRecordedPart(*prepared, part, sidecars, scans);
    const auto found = service::compareWithGolden(result, sidecars.forImage(part.file));
    matching += found.empty() ? 1 : 0;
    mismatches.insert(mismatches.end(), found.begin(), found.end());
  }
  const std::string title = "recipe " + std::to_string(prepared->recipe().id) + " " +
                            prepared->recipe().name + " (version " +
                            prepared->recipe().contentHash.substr(0, 12) + ")";
  if (opt.json) {
    nlohmann::json rows = nlohmann::json::array();
    for (const auto& m : mismatches)
      rows.push_back({{"file", m.file},
                      {"serial", m.serial},
                      {"check", m.check},
                      {"expected", m.expected},
                      {"got", m.got}});
    printJson({{"recipe",
                {{"id", prepared->recipe().id},
                 {"name", prepared->recipe().name},
                 {"version", prepared->recipe().contentHash}}},
               {"golden", opt.goldenFolder},
               {"parts", parts.size()},
               {"matching", matching},
               {"mismatches", rows}});
  } else {
    std::cout << title << " against " << opt.goldenFolder << ": " << parts.size() << " parts, "
              << matching << " as recorded, " << parts.size() - matching << " not\n";
    if (!mismatches.empty()) printTable(mismatches);
  }
  // CLI11's RuntimeError ends the program with this code and prints nothing more.
  if (!mismatches.empty()) throw CLI::RuntimeError(kMismatchExit);
}

}  // namespace

void addValidateCommand(CLI::App& app, const config::StepKindRegistry& kinds) {
  auto opt = std::make_shared<ValidateOptions>();
  auto* cmd = app.add_subcommand(
      "validate",
      "Golden-set gate: run a recipe over recorded parts with expected verdicts (and values); "
      "exit 3 on any mismatch");
  cmd->add_option("--recipe", opt->recipeFile, "Recipe file (YAML)")->required();
  cmd->add_option("--golden", opt->goldenFolder,
                  "Folder of recorded parts whose sidecars hold expected_verdict "
                  "(and optionally expected_values)")
      ->required();
  cmd->add_option("--station", opt->stationFile,
                  "Station config: calibration, recipe root and registers");
  cmd->add_option("--mm-per-pixel", opt->mmPerPixel,
                  "Calibration when no station is given (overrides the station's)");
  cmd->add_option("--glob", opt->glob, "File-name pattern in the folder (default: every image)");
  cmd->add_flag("--json", opt->json, "Print the result as one JSON object");
  cmd->callback([opt, &kinds] { runValidate(*opt, kinds); });
}

}  // namespace facet::cli
