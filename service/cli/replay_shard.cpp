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
#include "service/engine/warm_up.hpp"
#include "service/sinks/postgres_batch_writer.hpp"

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
  // Where the share goes: a new SQLite file, or the central database (resuming a share that
  // was partly written there before).
  std::unique_ptr<service::ResultsStore> store;
  std::unique_ptr<service::PostgresBatchWriter> central;
  std::string destination = opt.resultsFile;
  try {
    if (!opt.postgres.empty()) {
      const std::string station =
          opt.asStation.empty()
              ? "replay-" + recipe->recipe().name + "-" + recipe->recipe().contentHash.substr(0, 8)
              : opt.asStation;
      central = std::make_unique<service::PostgresBatchWriter>(opt.postgres, station);
      destination = "postgres " + central->peer() + " station " + station;
    } else {
      store = std::make_unique<service::ResultsStore>(opt.resultsFile);
    }
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (store && store->partCount() > 0)
    throw InputError(opt.resultsFile + ": holds parts already; a shard writes a new file");
  const auto sidecars = SidecarMetadata::loadFolder(opt.imagesFolder);
  std::map<std::string, int> counts{{"pass", 0}, {"fail", 0}, {"error", 0}};
  std::size_t skipped = 0;
  // The stored inspection times are those of a running station, which warms up before its first
  // part.
  service::warmUp(*recipe);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    for (const auto& part : share) {
      if (central && central->alreadyWritten().contains(part.partId)) {
        ++skipped;
        continue;
      }
      const auto result = service::inspectRecordedPart(*recipe, part, sidecars, scans);
      if (central)
        central->write(result);
      else
        store->store(result);
      ++counts[service::verdictName(result.verdict)];
    }
    if (central) central->finish();
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::size_t inspected = share.size() - skipped;
  const double rate = seconds > 0 ? static_cast<double>(inspected) / seconds : 0.0;
  if (opt.json) {
    printJson({{"shard", shard.text()},
               {"images", share.size()},
               {"counts", counts},
               {"seconds", seconds},
               {"skipped", skipped},
               {"images_per_second", rate},
               {"results", destination}});
    return;
  }
  std::cout << "shard " << shard.text() << ": " << share.size() << " parts, pass " << counts["pass"]
            << ", fail " << counts["fail"] << ", error " << counts["error"];
  if (skipped > 0) std::cout << ", " << skipped << " already in the database (skipped)";
  std::cout << " in " << seconds << " s (" << rate << " images/s)\nresults: " << destination
            << "\n";
}

}  // namespace facet::cli
