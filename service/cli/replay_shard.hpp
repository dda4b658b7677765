#pragma once
// `facet replay --shard I/N --results out.db`: this process's share of a batch re-inspection,
// written to a results store (SQLite) for `facet results merge`, or with `--postgres` to the
// central database under a station name of the batch's own. I/N also come from
// JOB_COMPLETION_INDEX / JOB_COMPLETIONS, as a Kubernetes Indexed Job sets them.

#include <string>

#include "config/step_kind.hpp"

namespace facet::cli {

struct ShardedReplayOptions {
  std::string recipeFile;
  std::string imagesFolder;
  std::string stationFile;
  double mmPerPixel = 0;
  std::string glob;
  std::string shard;        // "I/N"; empty: from the environment, else the whole folder
  std::string resultsFile;  // SQLite file to write (created; must not hold parts yet)
  std::string postgres;     // or: libpq connection string of the central database
  std::string asStation;    // the station name the parts get there; empty: replay-<recipe>-<hash>
  bool json = false;
};

void runShardedReplay(const ShardedReplayOptions& options, const config::StepKindRegistry& kinds);

}  // namespace facet::cli
