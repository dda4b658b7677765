#include "service/batch/shard.hpp"

#include <cstdlib>
#include <stdexcept>

namespace facet::service {
namespace {

int wholeNumber(const std::string& text, const std::string& what) {
  if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos)
    throw std::invalid_argument(what + " must be a whole number, not '" + text + "'");
  return std::stoi(text);
}

Shard checked(int index, int count, const std::string& text) {
  if (count < 1) throw std::invalid_argument("shard '" + text + "': the count must be at least 1");
  if (index >= count)
    throw std::invalid_argument("shard '" + text + "': the index counts from 0 and must be below " +
                                std::to_string(count));
  return {index, count};
}

}  // namespace

std::uint64_t stableNameHash(const std::string& text) {
  std::uint64_t h = 14695981039346656037ULL;  // FNV-1a offset basis
  for (const unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;  // FNV prime
  }
  return h;
}

bool Shard::takes(const std::filesystem::path& file) const {
  if (count <= 1) return true;
  // FNV-1a's low bits follow the last characters of similar names (part_1, part_2, ...): mixed
  // (MurmurHash3's finaliser) before the modulo so that every shard gets its share.
  std::uint64_t h = stableNameHash(file.filename().string());
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h % static_cast<std::uint64_t>(count) == static_cast<std::uint64_t>(index);
}

Shard parseShard(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos)
    throw std::invalid_argument("shard '" + text + "': expected I/N, e.g. 0/4");
  return checked(wholeNumber(text.substr(0, slash), "the shard index"),
                 wholeNumber(text.substr(slash + 1), "the shard count"), text);
}

std::optional<Shard> shardFromEnvironment() {
  const char* index = std::getenv("JOB_COMPLETION_INDEX");
  if (!index) return std::nullopt;
  const char* count = std::getenv("JOB_COMPLETIONS");
  if (!count)
    throw std::invalid_argument(
        "JOB_COMPLETION_INDEX is set but JOB_COMPLETIONS is not (set it to the Job's completions)");
  const std::string text = std::string(index) + "/" + count;
  return checked(wholeNumber(index, "JOB_COMPLETION_INDEX"), wholeNumber(count, "JOB_COMPLETIONS"),
                 text);
}

}  // namespace facet::service
