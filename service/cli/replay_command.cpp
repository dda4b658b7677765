// facet replay: runs one recipe over a recorded folder (the camera's replay backend, so sidecar
// files give each part its serial and expected verdict) and writes the HTML replay report.
#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <opencv2/imgproc.hpp>

#include "camera/camera_factory.hpp"
#include "camera/image_codecs.hpp"
#include "config/recipe_loader.hpp"
#include "config/station_config.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/replay_shard.hpp"
#include "service/daemon/part_banner.hpp"
#include "service/daemon/part_origin.hpp"
#include "service/daemon/process_capability.hpp"
#include "service/daemon/replay_report.hpp"
#include "service/engine/inspect_part.hpp"
#include "service/engine/overlay.hpp"
#include "service/engine/warm_up.hpp"

namespace facet::cli {
namespace {

struct ReplayOptions {
  std::string recipeFile;
  std::string imagesFolder;
  std::string reportFile;
  std::string stationFile;
  double mmPerPixel = 0;
  std::string glob;
  int thumbnailWidth = 320;
  bool json = false;
  std::string shard;        // batch re-inspection: I/N (replay_shard.hpp)
  std::string resultsFile;  // batch re-inspection: results store to write
  std::string postgres;     // batch re-inspection: or the central database
  std::string asStation;    // its station name there
};

std::string utcNow() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// The overlay picture of a failed part, full size and as a thumbnail of `width` pixels.
void pictures(const cv::Mat& image, const service::InspectionOutcome& o, const std::string& banner,
              int width, service::ReplayedPart& part) {
  cv::Mat picture =
      service::drawOverlay(image, o.overlay, banner, o.verdict == service::Verdict::Pass);
  encodeImage(".png", picture, part.overlayPng);
  if (picture.cols > width) {
    const double scale = static_cast<double>(width) / picture.cols;
    cv::resize(picture, picture, {}, scale, scale, cv::INTER_AREA);
  }
  encodeImage(".png", picture, part.thumbnailPng);
}

void runReplay(const ReplayOptions& opt, const config::StepKindRegistry& kinds) {
  // The camera module logs through spdlog, whose default logger writes to stdout: keep stdout
  // for the one JSON object.
  spdlog::set_default_logger(spdlog::stderr_color_mt("facet-replay"));
  // Calibration and recipe root come from the station when one is given.
  config::RecipeLoadOptions loadOptions;
  config::Calibration calibration;
  double mmPerPixel = opt.mmPerPixel;
  if (!opt.stationFile.empty()) {
    const auto station = config::loadStationConfig(opt.stationFile);
    if (!station.station)
      throw InputError(station.diagnostics.text() + opt.stationFile +
                       ": station config has errors");
    loadOptions = station.station->recipeLoadOptions();
    calibration = station.station->calibration;
    if (mmPerPixel <= 0) mmPerPixel = station.station->calibration.mmPerPixel;
  }
  if (mmPerPixel <= 0)
    throw InputError("replay: give --station (for its calibration) or --mm-per-pixel > 0");
  calibration.mmPerPixel = mmPerPixel;
  const auto loaded = config::loadRecipe(opt.recipeFile, kinds, loadOptions);
  if (!loaded.recipe)
    throw InputError(loaded.diagnostics.text() + opt.recipeFile + ": recipe has errors");
  std::shared_ptr<const service::PreparedRecipe> recipe;
  try {
    recipe =
        service::prepareRecipe(std::make_shared<const config::Recipe>(*loaded.recipe), calibration);
  } catch (const service::InspectionSetupError& e) {
    throw InputError(opt.recipeFile + ": " + e.what());
  }

  CameraSettings settings;
  settings.backend = CameraBackend::Replay;
  settings.replay.folder = opt.imagesFolder;
  settings.replay.glob = opt.glob;
  settings.replay.loop = false;
  settings.replay.trigger = TriggerMode::FreeRun;
  std::unique_ptr<Camera> camera;
  try {
    camera = makeCamera(settings);
    camera->open();
    camera->start();
  } catch (const std::exception& e) {
    throw InputError(opt.imagesFolder + ": " + e.what());
  }

  // Checked once recipe and folder are fine, before spending time on the folder.
  std::ofstream out(opt.reportFile);
  if (!out) throw InputError(opt.reportFile + ": cannot write the report");

  service::ReplayReport report;
  report.title = "recipe " + std::to_string(loaded.recipe->id) + " " + loaded.recipe->name;
  report.recipeFile = opt.recipeFile;
  report.imagesFolder = opt.imagesFolder;
  report.mmPerPixel = mmPerPixel;
  report.generatedAt = utcNow();
  // The report's times are those of a running station, which warms up before its first part.
  service::warmUp(*recipe);
  for (std::uint64_t partId = 1;; ++partId) {
    auto grab = camera->grab(std::chrono::milliseconds(5000));
    if (grab.status == GrabStatus::EndOfStream) break;
    service::ReplayedPart part;
    service::PartResult& p = part.result;
    p.partId = partId;
    p.time = std::chrono::system_clock::now();
    service::recordPartOrigin(p, &*loaded.recipe, grab.frame);
    if (!grab.ok()) {
      // A file the replay could not use is a part that was not inspected.
      p.verdict = service::Verdict::Error;
      p.error = std::string(toString(grab.status)) + ": " + grab.message;
      if (grab.status == GrabStatus::Timeout || grab.status == GrabStatus::NotStarted) break;
      report.parts.push_back(std::move(part));
      continue;
    }
    const auto outcome =
        service::inspectPart({.image = grab.frame.image, .scan = std::nullopt}, *recipe);
    service::recordOutcome(p, outcome);
    if (p.verdict != service::Verdict::Pass) {
      pictures(grab.frame.image, outcome,
               service::partBanner(p, p.serial.empty() ? p.source : p.serial), opt.thumbnailWidth,
               part);
    }
    report.parts.push_back(std::move(part));
  }
  camera->stop();
  camera->close();
  if (report.parts.empty()) throw InputError(opt.imagesFolder + ": no image to replay");

  service::writeReplayReport(report, out);
  out.close();
  if (!out) throw InputError(opt.reportFile + ": writing the report failed");

  std::map<std::string, int> counts{{"pass", 0}, {"fail", 0}, {"error", 0}};
  int unexpected = 0;
  std::vector<service::PartResult> results;
  for (const auto& part : report.parts) {
    ++counts[service::verdictName(part.result.verdict)];
    unexpected += service::verdictUnexpected(part.result) ? 1 : 0;
    results.push_back(part.result);
  }
  const auto caps = service::processCapability(results);
  if (opt.json) {
    nlohmann::json capability = nlohmann::json::array();
    for (const auto& c : caps) {
      nlohmann::json j{
          {"name", c.name}, {"unit", c.unit}, {"n", c.count}, {"mean", c.mean}, {"sigma", c.sigma}};
      j["cp"] = c.cp ? nlohmann::json(*c.cp) : nullptr;
      j["cpk"] = c.cpk ? nlohmann::json(*c.cpk) : nullptr;
      j["index"] = c.index;  // Cpk, or Cpu / Cpl where a limit is a natural bound
      capability.push_back(j);
    }
    printJson({{"recipe", {{"id", loaded.recipe->id}, {"name", loaded.recipe->name}}},
               {"images", report.parts.size()},
               {"counts", counts},
               {"unexpected", unexpected},
               {"capability", capability},
               {"report", opt.reportFile}});
    return;
  }
  std::cout << report.title << ": " << report.parts.size() << " parts, pass " << counts["pass"]
            << ", fail " << counts["fail"] << ", error " << counts["error"] << ", unexpected "
            << unexpected << "\nreport: " << opt.reportFile << "\n";
}

}  // namespace

void addReplayCommand(CLI::App& app, const config::StepKindRegistry& kinds) {
  auto opt = std::make_shared<ReplayOptions>();
  auto* cmd =
      app.add_subcommand("replay", "Run a recipe over a recorded folder and write an HTML report");
  cmd->add_option("--recipe", opt->recipeFile, "Recipe file (YAML)")->required();
  cmd->add_option("--images", opt->imagesFolder, "Folder of recorded images (with sidecars)")
      ->required();
  cmd->add_option("--report", opt->reportFile, "HTML report to write");
  cmd->add_option("--results", opt->resultsFile,
                  "Batch re-inspection: write every part to this results store (SQLite) instead "
                  "of a report");
  auto* postgres = cmd->add_option(
      "--postgres", opt->postgres,
      "Batch re-inspection: write every part to the central PostgreSQL database instead (a libpq "
      "connection string; the password from PGPASSWORD or ~/.pgpass). Parts the station name "
      "has there already are skipped: a restarted shard resumes");
  cmd->add_option("--as-station", opt->asStation,
                  "With --postgres: the station name of the parts (default: "
                  "replay-<recipe name>-<first 8 digits of the recipe's hash>)")
      ->needs(postgres);
  cmd->add_option("--shard", opt->shard,
                  "Batch re-inspection: take share I of N (0-based, by a hash of the file name; "
                  "default: JOB_COMPLETION_INDEX/JOB_COMPLETIONS when set); needs --results or "
                  "--postgres");
  cmd->add_option("--station", opt->stationFile,
                  "Station config: calibration, recipe root and registers");
  cmd->add_option("--mm-per-pixel", opt->mmPerPixel,
                  "Calibration when no station is given (overrides the station's)");
  cmd->add_option("--glob", opt->glob, "File-name pattern in the folder (default: every image)");
  cmd->add_option("--thumbnail-width", opt->thumbnailWidth, "Width of failed-part thumbnails, px")
      ->check(CLI::Range(32, 4096));
  cmd->add_flag("--json", opt->json, "Print a summary as one JSON object");
  cmd->callback([opt, &kinds] {
    if (!opt->resultsFile.empty() || !opt->postgres.empty() || !opt->shard.empty()) {
      if (opt->resultsFile.empty() && opt->postgres.empty())
        throw InputError("replay --shard: give --results FILE.db or --postgres CONNECTION");
      if (!opt->resultsFile.empty() && !opt->postgres.empty())
        throw InputError("replay: --results and --postgres exclude each other");
      if (!opt->reportFile.empty())
        throw InputError("replay: --report and --results/--postgres exclude each other");
      runShardedReplay({.recipeFile = opt->recipeFile,
                        .imagesFolder = opt->imagesFolder,
                        .stationFile = opt->stationFile,
                        .mmPerPixel = opt->mmPerPixel,
                        .glob = opt->glob,
                        .shard = opt->shard,
                        .resultsFile = opt->resultsFile,
                        .postgres = opt->postgres,
                        .asStation = opt->asStation,
                        .json = opt->json},
                       kinds);
      return;
    }
    if (opt->reportFile.empty()) throw InputError("replay: give --report FILE.html or --results");
    runReplay(*opt, kinds);
  });
}

}  // namespace facet::cli
