#pragma once
// Batch re-inspection of recorded parts: a folder of images (or, for scan recipes, of CSV range
// scans), each with its sidecar, inspected one by one without a camera or a daemon. Used by
// `facet replay --shard` / `--results` and by `facet validate`.
//
// A part's id is its position in the whole folder's natural order (from 1), whatever shard
// inspects it, so the shards' results merge into exactly the rows of one unsharded run.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "camera/sidecar_metadata.hpp"
#include "service/batch/shard.hpp"
#include "service/engine/inspect_part.hpp"
#include "service/engine/part_result.hpp"

namespace facet::service {

struct RecordedPart {
  std::filesystem::path file;
  std::uint64_t partId = 0;
};

// The recorded parts of `folder` that `shard` takes: images matching `glob` (every image file
// when empty), or *.csv scans when `scans`. Throws std::runtime_error when the folder cannot
// be read.
std::vector<RecordedPart> listShare(const std::filesystem::path& folder, const std::string& glob,
                                    bool scans, const Shard& shard);

// True when no step of the recipe needs the camera image: its recorded parts are range scans.
inline bool scanRecipe(const PreparedRecipe& recipe) {
  return !recipe.needsImage;
}

// Reads and inspects one recorded part. Never throws: a file that cannot be read is a part with
// Verdict::Error naming the cause (never a good part).
PartResult inspectRecordedPart(const PreparedRecipe& recipe, const RecordedPart& part,
                               const SidecarMetadata& sidecars, bool scan);

}  // namespace facet::service
