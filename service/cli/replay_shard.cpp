#include "service/cli/replay_shard.hpp"

#include <chrono>
#include <iostream>
#include <map>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "service/batch/batch_replay.hpp"
#include "service/cli/batch_inspection.hpp"
#include "service/cli/command_line.hpp"
#include "service/daemon/results_store.hpp"

namespace facet::cli {

void runShardedReplay(const ShardedReplayOptions& opt, const config::StepKindRegistry& kinds) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("facet-replay-shard"));
  service::Shard shard;
  try {
    if (!opt.shard.empty())
      shard = service::parseShard(opt.shard);
    else if (const auto fromJob = service::shardFromEnvironment())
      shard = *fromJob;
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--shard: ") + e.what());
  }
  const auto recipe = loadRecipeForBatch(opt.recipeFile, opt.stationFile, opt.mmPerPixel, kinds);
  const bool scans = service::scanRecipe(*recipe);
  std::vector<service::RecordedPart> share;
  try {
    share = service::listShare(opt.imagesFolder, opt.glob, scans, shard);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  std::unique_ptr<service::ResultsStore> store;
  try {
    store = std::make_unique<service::ResultsStore>(opt.resultsFile);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (store->partCount() > 0)
    throw InputError(opt.resultsFile + ": holds parts already; a shard writes a new file");
  const auto sidecars = SidecarMetadata::loadFolder(opt.imagesFolder);
  std::map<std::string, int> counts{{"pass", 0}, {"fail", 0}, {"error", 0}};
  const auto t0 = std::chrono::steady_clock::now();
  for (const auto& part : share) {
    const auto result = service::inspectRecordedPart(*recipe, part, sidecars, scans);
    store->store(result);
    ++counts[service::verdictName(result.verdict)];
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = seconds > 0 ? static_cast<double>(share.size()) / seconds : 0.0;
  if (opt.json) {
    printJson({{"shard", shard.text()},
               {"images", share.size()},
               {"counts", counts},
               {"seconds", seconds},
               {"images_per_second", rate},
               {"results", opt.resultsFile}});
    return;
  }
  std::cout << "shard " << shard.text() << ": " << share.size() << " parts, pass " << counts["pass"]
            << ", fail " << counts["fail"] << ", error " << counts["error"] << " in " << seconds
            << " s (" << rate << " images/s)\nresults: " << opt.resultsFile << "\n";
}

}  // namespace facet::cli
