#include "service/sinks/postgres_sink.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "config/libpq_library.hpp"
#include "service/daemon/results_store.hpp"
#include "service/sinks/fleet_message.hpp"
#include "service/sinks/postgres_connection.hpp"

namespace facet::service {

const char* const kPostgresSchema = R"sql(
CREATE TABLE IF NOT EXISTS parts (
  station        TEXT NOT NULL,
  part_id        BIGINT NOT NULL,
  time_us        BIGINT NOT NULL,
  time_utc       TIMESTAMPTZ NOT NULL,
  recipe_id      INTEGER NOT NULL,
  recipe_name    TEXT NOT NULL,
  recipe_version TEXT NOT NULL,
  frame_id       BIGINT NOT NULL,
  source         TEXT NOT NULL,
  serial         TEXT NOT NULL,
  expected       TEXT NOT NULL,
  verdict        TEXT NOT NULL CHECK (verdict IN ('pass', 'fail', 'error')),
  failed_checks  TEXT NOT NULL,
  error          TEXT NOT NULL,
  inspection_ms  DOUBLE PRECISION NOT NULL,
  timings_json   TEXT NOT NULL,
  defect         TEXT NOT NULL DEFAULT '',
  notes          TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (station, part_id, time_us)
);
-- A database made before parts had `defect` (a recorded part's known fault) or `notes` (one a
-- line) gains them.
ALTER TABLE parts ADD COLUMN IF NOT EXISTS defect TEXT NOT NULL DEFAULT '';
ALTER TABLE parts ADD COLUMN IF NOT EXISTS notes TEXT NOT NULL DEFAULT '';
CREATE INDEX IF NOT EXISTS parts_time ON parts(time_utc);
CREATE TABLE IF NOT EXISTS measurements (
  station   TEXT NOT NULL,
  part_id   BIGINT NOT NULL,
  time_us   BIGINT NOT NULL,
  name      TEXT NOT NULL,
  value     DOUBLE PRECISION,
  unit      TEXT NOT NULL,
  nominal   DOUBLE PRECISION,
  tol_minus DOUBLE PRECISION,
  tol_plus  DOUBLE PRECISION,
  checked   BOOLEAN NOT NULL,
  pass      BOOLEAN NOT NULL,
  PRIMARY KEY (station, part_id, time_us, name),
  FOREIGN KEY (station, part_id, time_us) REFERENCES parts ON DELETE CASCADE
);
)sql";

bool createPostgresSchema(pg_conn* conn) {
  // One implicit transaction: the lock is held until the last CREATE is committed. The server's
  // "already exists, skipping" notices would reach stderr at every connection.
  const std::string locked =
      std::string(
          "SET LOCAL client_min_messages = warning;"
          "SELECT pg_advisory_xact_lock(hashtext('facet results schema'));") +
      kPostgresSchema;
  return succeeded(PgResult(config::libpq().exec(conn, locked.c_str())));
}

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

std::optional<std::string> number(const std::optional<double>& v) {
  if (!v || !std::isfinite(*v)) return std::nullopt;
  return fmt::format("{}", *v);
}

constexpr const char* kInsertPart =
    "INSERT INTO parts VALUES ($1, $2, $3, to_timestamp($3::bigint / 1000000.0::float8), $4, $5, "
    "$6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17) ON CONFLICT DO NOTHING";
constexpr const char* kInsertValue =
    "INSERT INTO measurements VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11)";

}  // namespace

PostgresSink::PostgresSink(config::PostgresSettings settings, std::string station)
    : settings_(std::move(settings)),
      station_(std::move(station)),
      outbox_(settings_.outbox.folder,
              static_cast<std::uint64_t>(settings_.outbox.quotaMb * 1024 * 1024),
              "postgres outbox") {
  status_.name = "postgres";
  status_.peer = postgresPeer(settings_.connection);
  status_.lastError = "not connected yet";
}

PostgresSink::~PostgresSink() {
  stop(0ms);
  if (conn_) config::libpq().finish(conn_);
}

void PostgresSink::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
}

void PostgresSink::submit(const PartResult& part) {
  outbox_.append(fleetMessage(station_, part).dump());
}

void PostgresSink::stop(std::chrono::milliseconds flush) {
  if (!thread_.joinable()) return;
  flushDeadline_ = Clock::now() + flush;
  stopping_ = true;
  outbox_.wake();
  thread_.join();
}

SinkStatus PostgresSink::status() const {
  std::lock_guard lock(statusMutex_);
  SinkStatus s = status_;
  s.outbox = outbox_.stats();
  return s;
}

void PostgresSink::setError(std::string error) {
  std::lock_guard lock(statusMutex_);
  if (error != status_.lastError)
    spdlog::warn("postgres {}: {} (results wait in {})", status_.peer, error,
                 outbox_.folder().string());
  status_.lastError = std::move(error);
  status_.connected = false;
}

void PostgresSink::sleepFor(std::chrono::milliseconds wait) {
  const auto until = Clock::now() + wait;
  while (!stopping_ && Clock::now() < until) std::this_thread::sleep_for(20ms);
}

bool PostgresSink::connect() {
  const config::LibPq* loaded = nullptr;
  try {
    loaded = &config::libpq();
  } catch (const std::runtime_error& e) {
    setError(e.what());  // kept and retried, as a server away would be
    return false;
  }
  const config::LibPq& pq = *loaded;
  const std::string timeout = std::to_string(settings_.connectTimeoutS);
  const std::string application = "facet-" + station_;
  std::vector<const char*> keys{"dbname", "connect_timeout", "application_name"};
  std::vector<const char*> values{settings_.connection.c_str(), timeout.c_str(),
                                  application.c_str()};
  if (!settings_.password.empty()) {
    keys.push_back("password");
    values.push_back(settings_.password.c_str());
  }
  keys.push_back(nullptr);
  values.push_back(nullptr);
  // expand_dbname = 1: the first value is the whole connection string.
  conn_ = pq.connectdbParams(keys.data(), values.data(), 1);
  if (pq.status(conn_) != CONNECTION_OK) {
    std::string why = postgresError(conn_);
    if (why.find("password authentication failed") != std::string::npos ||
        why.find("no password supplied") != std::string::npos)
      why += " (check postgres.connection's user and postgres.password)";
    setError("cannot connect: " + why);
    pq.finish(conn_);
    conn_ = nullptr;
    return false;
  }
  if (!createPostgresSchema(conn_)) {
    setError("cannot create the tables: " + postgresError(conn_));
    pq.finish(conn_);
    conn_ = nullptr;
    return false;
  }
  std::lock_guard lock(statusMutex_);
  status_.connected = true;
  status_.lastError.clear();
  ++status_.connects;
  spdlog::info("postgres {}: connected; {} results waiting", status_.peer, outbox_.stats().pending);
  return true;
}

bool PostgresSink::write(const std::vector<OutboxRecord>& records) {
  const config::LibPq& pq = config::libpq();  // loaded: there is a connection
  auto rollback = [&] { pq.clear(pq.exec(conn_, "ROLLBACK")); };
  if (!succeeded(PgResult(pq.exec(conn_, "BEGIN")))) return false;
  std::vector<std::uint64_t> done;
  for (const auto& record : records) {
    std::string station;
    PartResult p;
    try {
      p = partFromFleetMessage(nlohmann::json::parse(record.payload), &station);
    } catch (const std::exception& e) {
      // Not a message of ours (a damaged file): it would block the outbox forever.
      spdlog::error("postgres outbox: record {} dropped: {}", record.seq, e.what());
      done.push_back(record.seq);
      continue;
    }
    const std::string partId = std::to_string(p.partId);
    const std::string timeUs = std::to_string(
        std::chrono::duration_cast<std::chrono::microseconds>(p.time.time_since_epoch()).count());
    const PgResult part = executeWithText(
        conn_, kInsertPart,
        {station, partId, timeUs, std::to_string(p.recipeId), p.recipeName, p.recipeVersion,
         std::to_string(p.frameId), p.source, p.serial, p.expectedVerdict,
         std::string(verdictName(p.verdict)), joinedChecks(p.failedChecks, ','), p.error,
         fmt::format("{}", p.inspectionMs), timingsText(p.timings), p.recordedDefect,
         joinedChecks(p.notes, '\n')});
    if (!succeeded(part)) {
      spdlog::error("postgres: part {}: {}", p.partId, postgresError(conn_));
      rollback();
      return false;
    }
    // 0 rows: the part is there already (sent again after a lost COMMIT answer).
    if (std::string(pq.cmdTuples(part.get())) == "1") {
      for (const auto& m : p.measurements) {
        const PgResult value = executeWithText(
            conn_, kInsertValue,
            {station, partId, timeUs, m.name, number(m.value), m.unit, number(m.nominal),
             number(m.tolMinus), number(m.tolPlus), std::string(m.checked ? "true" : "false"),
             std::string(m.pass ? "true" : "false")});
        if (!succeeded(value)) {
          spdlog::error("postgres: part {} value {}: {}", p.partId, m.name, postgresError(conn_));
          rollback();
          return false;
        }
      }
    }
    done.push_back(record.seq);
  }
  if (!succeeded(PgResult(pq.exec(conn_, "COMMIT")))) return false;
  outbox_.remove(done);
  std::lock_guard lock(statusMutex_);
  status_.delivered += done.size();
  return true;
}

void PostgresSink::run() {
  auto backoff = 100ms;
  while (true) {
    if (stopping_ && (outbox_.stats().pending == 0 || Clock::now() >= flushDeadline_ || !conn_))
      break;
    if (!conn_) {
      if (connect()) {
        backoff = 100ms;
      } else {
        sleepFor(backoff);
        backoff = std::min<std::chrono::milliseconds>(
            backoff * 2, std::chrono::milliseconds(settings_.reconnectMaxMs));
        continue;
      }
    }
    if (!outbox_.waitForRecords(200ms)) continue;
    const auto records = outbox_.peek(static_cast<std::size_t>(settings_.batchParts));
    if (records.empty() || write(records)) continue;
    // Failed: a lost connection is reconnected; a statement the server refused (a bug, a
    // changed table) is logged and retried after the back-off, never silently skipped.
    const config::LibPq& pq = config::libpq();  // loaded: there was a connection
    const bool lost = pq.status(conn_) != CONNECTION_OK;
    setError((lost ? "connection lost: " : "write failed: ") + postgresError(conn_));
    pq.finish(conn_);
    conn_ = nullptr;
    sleepFor(backoff);
    backoff = std::min<std::chrono::milliseconds>(
        backoff * 2, std::chrono::milliseconds(settings_.reconnectMaxMs));
  }
  std::lock_guard lock(statusMutex_);
  status_.connected = false;
  status_.lastError = "stopped";
}

}  // namespace facet::service
