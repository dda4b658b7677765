#pragma once
// The station's results store: one SQLite file, one row per part (and one row per measured value),
// in WAL mode so that a crash or SIGKILL leaves a consistent database.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "service/daemon/part_export.hpp"  // toJson and toCsv for the store's users
#include "service/engine/part_result.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace facet::service {

// The columns of the parts table, in the order the store writes them (the merge of shard stores
// copies them by name).
inline constexpr const char* kStoredPartColumns =
    "part_id, time_us, time_utc, recipe_id, recipe_name, recipe_version, frame_id, source, "
    "serial, expected, verdict, failed_checks, error, inspection_ms, timings_json, defect, notes";

// Columns added after the first stores were written (TEXT, '' by default): an older store gains
// them when opened, and the merge reads '' from an older shard.
inline constexpr const char* kLaterPartColumns[] = {"defect", "notes"};

struct RetentionPolicy {
  std::optional<std::chrono::seconds> maxAge;  // parts older than this are deleted (none = keep)
  std::optional<std::int64_t> maxParts;        // keep at most this many newest parts (none = all)
};

class ResultsStore {
 public:
  // Opens (creating when missing) the database file. Throws std::runtime_error naming the file.
  explicit ResultsStore(const std::filesystem::path& file, RetentionPolicy retention = {});
  ~ResultsStore();
  ResultsStore(const ResultsStore&) = delete;
  ResultsStore& operator=(const ResultsStore&) = delete;

  // Stores one part in one transaction. Throws on failure (the caller counts and logs it).
  void store(const PartResult& part);

  // Applies the retention policy, oldest parts first, at most `limit` parts (0 = all); returns
  // the number of parts deleted. A limit bounds the time the store is held (about 11 us per
  // part with its measurements here), so a caller between two parts can do it in slices.
  std::int64_t applyRetention(std::chrono::system_clock::time_point now, std::int64_t limit = 0);

  [[nodiscard]] std::int64_t partCount() const;
  // The highest stored part id (0 when empty): a restarted daemon continues after it.
  [[nodiscard]] std::uint64_t lastPartId() const;

  // Parts at or after `since` (oldest first), at most `limit` (0 = all).
  [[nodiscard]] std::vector<PartResult> query(std::chrono::system_clock::time_point since,
                                              std::size_t limit = 0) const;
  // Parts with id > afterPartId, oldest first, at most `limit` (0 = all): a client pages through
  // the store by passing the last id it got, and misses nothing however many parts arrived.
  [[nodiscard]] std::vector<PartResult> partsAfter(std::uint64_t afterPartId,
                                                   std::size_t limit) const;
  // The `count` newest parts, newest last.
  [[nodiscard]] std::vector<PartResult> latest(std::size_t count) const;

  // "ok" when PRAGMA integrity_check passes, otherwise its first message.
  [[nodiscard]] std::string integrityCheck() const;

  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  std::vector<PartResult> select(const std::string& where, const std::string& order,
                                 std::int64_t bind, std::size_t limit) const;
  std::filesystem::path file_;
  RetentionPolicy retention_;
  sqlite3* db_ = nullptr;
};

}  // namespace facet::service
