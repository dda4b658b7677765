#pragma once
// `facet results merge A.db B.db ... --out all.db`: joins results stores (the shards of a batch
// re-inspection, or several stations' files) into a new one, row for row. Part ids must not
// repeat across the inputs: two shards that overlap, or one file given twice, are refused.

#include <cstdint>
#include <filesystem>
#include <vector>

namespace facet::service {

struct MergedInput {
  std::filesystem::path file;
  std::int64_t parts = 0;
  std::int64_t measurements = 0;
};

// Creates `out` (which must not exist) and copies every input into it in one transaction per
// input. Throws std::runtime_error naming the file (and the repeated part id); `out` is removed
// again on failure.
std::vector<MergedInput> mergeResults(const std::vector<std::filesystem::path>& inputs,
                                      const std::filesystem::path& out);

}  // namespace facet::service
