#pragma once
// PostgresBatchWriter: a batch re-inspection's parts (`facet replay --postgres`) into the central
// PostgreSQL database, under a station name of the batch's own, so that a plant compares a
// changed recipe's verdicts with the line's in one place.
//
// It writes through a PostgresSink (same tables, same idempotent transactions, reconnection
// with back-off) whose outbox lives in a temporary folder. Unlike a station it must never drop
// a part: a database slower than the inspection makes write() wait, and finish() fails when
// parts could not be written. A shard that is started again (a pod of an Indexed Job retried
// after a crash) skips the parts its station already has in the database: resuming, never
// writing a part twice.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <set>
#include <string>

#include "service/engine/part_result.hpp"
#include "service/sinks/postgres_sink.hpp"

namespace facet::service {

class PostgresBatchWriter {
 public:
  // Connects once: creates the tables when missing and reads which part ids `station` has
  // there already. `connection`: a libpq connection string; the password from it, PGPASSWORD
  // or ~/.pgpass. Throws std::runtime_error naming the server (never the password).
  PostgresBatchWriter(std::string connection, std::string station);
  ~PostgresBatchWriter();
  PostgresBatchWriter(const PostgresBatchWriter&) = delete;
  PostgresBatchWriter& operator=(const PostgresBatchWriter&) = delete;

  // Part ids of the station already in the database when the writer connected.
  [[nodiscard]] const std::set<std::uint64_t>& alreadyWritten() const { return already_; }
  // Queues one part. Waits while many parts are unwritten; throws std::runtime_error when the
  // database has taken none of them for two minutes.
  void write(const PartResult& part);
  // Waits until every part is written (or throws as write() does), then disconnects.
  void finish();
  [[nodiscard]] std::string peer() const { return sink_->status().peer; }

 private:
  // Waits until at most `pending` parts are unwritten.
  void drainTo(std::uint64_t pending);

  std::set<std::uint64_t> already_;
  std::filesystem::path outbox_;
  std::unique_ptr<PostgresSink> sink_;
};

}  // namespace facet::service
