#pragma once
// Outbox: results waiting on disk for a sink (MQTT broker, PostgreSQL) that may be away.
//
// One file per record in a folder of its own, named by a sequence number, so the order survives
// a restart of facetd and a record is either wholly there or not at all (written to a temporary
// name, then renamed). Appending never waits for the sink: when the folder would exceed its
// quota, the oldest records are deleted, counted and logged. The files are not fsync'ed: they
// survive a killed or crashed facetd, not a power cut.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

namespace facet::service {

struct OutboxRecord {
  std::uint64_t seq = 0;
  std::string payload;
};

struct OutboxStats {
  std::uint64_t pending = 0;      // records waiting
  std::uint64_t bytes = 0;        // their size on disk
  std::uint64_t appended = 0;     // since start
  std::uint64_t dropped = 0;      // oldest records deleted because the quota was full
  std::uint64_t writeErrors = 0;  // records that could not be written (counted, logged)
  std::uint64_t recovered = 0;    // records found in the folder at start
};

class Outbox {
 public:
  // Opens (creating when missing) `folder` and takes over the records a previous run left.
  // `name` prefixes log lines ("mqtt outbox"). Throws std::runtime_error naming the folder
  // when it cannot be created or listed.
  Outbox(std::filesystem::path folder, std::uint64_t quotaBytes, std::string name);

  // Adds a record at the end; returns false when it could not be written (disk full, folder
  // gone), which is counted and logged here.
  bool append(const std::string& payload);
  // The `max` oldest records, oldest first (read from their files; an unreadable one is dropped
  // and counted).
  std::vector<OutboxRecord> peek(std::size_t max);
  // Deletes delivered records (a record already dropped for the quota is skipped).
  void remove(const std::vector<std::uint64_t>& seqs);
  // Waits until a record is there or `timeout` passed; returns whether one is there.
  bool waitForRecords(std::chrono::milliseconds timeout);
  // Wakes waitForRecords() (at stop).
  void wake();

  [[nodiscard]] OutboxStats stats() const;
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path fileOf(std::uint64_t seq) const;
  void dropOldestLocked();

  struct Entry {
    std::uint64_t seq;
    std::uint64_t bytes;
  };
  std::filesystem::path folder_;
  std::uint64_t quotaBytes_;
  std::string name_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Entry> entries_;  // oldest first
  std::uint64_t nextSeq_ = 1;
  OutboxStats stats_;
  bool woken_ = false;
};

}  // namespace facet::service
