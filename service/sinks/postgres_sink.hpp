#pragma once
// PostgresSink: the station's results in a central PostgreSQL database, in the tables of the
// SQLite results store (`parts`, `measurements`) with a `station` column more, so that one
// database takes a whole plant.
//
// As with MQTT, submit() only appends to an outbox on disk; a thread of its own writes the
// outbox to the database in transactions of up to `batch_parts` parts and deletes the records
// after COMMIT. Writing is idempotent: a part is keyed by (station, part_id, time_us), and a
// part already there (its COMMIT reached the server but the answer was lost with the
// connection) is skipped, so no part is written twice after a restart of either side.

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "config/fleet_settings.hpp"
#include "service/engine/part_result.hpp"
#include "service/sinks/outbox.hpp"
#include "service/sinks/sink_status.hpp"

struct pg_conn;

namespace facet::service {

// The schema, created when missing (CREATE TABLE IF NOT EXISTS): the results store's columns.
extern const char* const kPostgresSchema;

// Creates the schema when missing. Stations and replay shards that connect at the same moment
// are serialised by an advisory lock: two concurrent CREATE TABLE IF NOT EXISTS of one table
// can otherwise both try to create it and one fails. False: see postgresError(conn).
bool createPostgresSchema(pg_conn* conn);

class PostgresSink {
 public:
  PostgresSink(config::PostgresSettings settings, std::string station);
  ~PostgresSink();
  PostgresSink(const PostgresSink&) = delete;
  PostgresSink& operator=(const PostgresSink&) = delete;

  void start();
  void submit(const PartResult& part);
  // Writes what is left for at most `flush`, then closes the connection.
  void stop(std::chrono::milliseconds flush = std::chrono::milliseconds(2000));

  [[nodiscard]] SinkStatus status() const;

 private:
  void run();
  bool connect();
  // Writes `records` in one transaction; returns false when the connection failed.
  bool write(const std::vector<OutboxRecord>& records);
  void setError(std::string error);
  void sleepFor(std::chrono::milliseconds wait);

  config::PostgresSettings settings_;
  std::string station_;
  Outbox outbox_;
  pg_conn* conn_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::chrono::steady_clock::time_point flushDeadline_;
  mutable std::mutex statusMutex_;
  SinkStatus status_;
};

}  // namespace facet::service
