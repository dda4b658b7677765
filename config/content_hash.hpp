#pragma once
// Content hashes that tell whether a file changed: FNV-1a 64, printed as 16 hex digits. Not a
// security measure, only change detection.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace facet::config {

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t seed = 0xcbf29ce484222325ULL);
std::string hexHash(std::uint64_t hash);
// The file's hash, or nullopt when it cannot be read.
std::optional<std::string> fileHash(const std::filesystem::path& file);

}  // namespace facet::config
