#pragma once
// One shard of a batch re-inspection: `facet replay --shard I/N` takes the images whose file
// name hashes to I modulo N. The share depends only on the file name (FNV-1a, 64 bit), never on
// the listing order or on which machine lists the folder, so N independent processes (a
// Kubernetes Indexed Job) cover every image exactly once, and a re-run takes the same files.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace facet::service {

struct Shard {
  int index = 0;  // 0 .. count-1
  int count = 1;

  [[nodiscard]] bool takes(const std::filesystem::path& file) const;
  [[nodiscard]] std::string text() const {
    return std::to_string(index) + "/" + std::to_string(count);
  }
};

// 64-bit FNV-1a of the bytes of `text`: fixed by its definition, so shards agree across
// versions, compilers and machines (std::hash does not promise that).
std::uint64_t stableNameHash(const std::string& text);

// "I/N" with 0 <= I < N. Throws std::invalid_argument with a message saying what is wrong.
Shard parseShard(const std::string& text);

// From JOB_COMPLETION_INDEX and JOB_COMPLETIONS (a Kubernetes Indexed Job sets the index; the
// manifest passes the count); nullopt when JOB_COMPLETION_INDEX is not set. Throws
// std::invalid_argument when they are set but not usable.
std::optional<Shard> shardFromEnvironment();

}  // namespace facet::service
