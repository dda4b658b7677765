#include "service/sinks/postgres_batch_writer.hpp"

#include <stdlib.h>

#include <stdexcept>
#include <thread>

#include "config/libpq_library.hpp"
#include "service/sinks/postgres_connection.hpp"

namespace facet::service {
namespace {

using namespace std::chrono_literals;

// Parts queued ahead of the database at most: bounds the outbox on disk (a few MB), whatever
// the number of images.
constexpr std::uint64_t kMaxQueued = 2000;
// How long the database may take no part before the batch gives up: longer than a server
// restart, shorter than anyone would wait for a stuck job.
constexpr auto kPatience = 120s;

std::filesystem::path temporaryOutbox() {
  std::string pattern = (std::filesystem::temp_directory_path() / "facet-replay-outbox-XXXXXX");
  if (!::mkdtemp(pattern.data()))
    throw std::runtime_error("cannot make a temporary folder in " +
                             std::filesystem::temp_directory_path().string());
  return pattern;
}

}  // namespace

PostgresBatchWriter::PostgresBatchWriter(std::string connection, std::string station) {
  const std::string peer = postgresPeer(connection);
  {
    const PgConnection conn = connectOrThrow(connection);
    if (!createPostgresSchema(conn.get()))
      throw std::runtime_error("postgres " + peer +
                               ": cannot create the tables: " + postgresError(conn.get()));
    const PgResult ids = executeWithText(conn.get(), "SELECT part_id FROM parts WHERE station = $1",
                                         {std::optional(station)});
    if (!succeeded(ids))
      throw std::runtime_error("postgres " + peer +
                               ": cannot read the station's parts: " + postgresError(conn.get()));
    const config::LibPq& pq = config::libpq();
    for (int row = 0; row < pq.ntuples(ids.get()); ++row)
      already_.insert(std::stoull(pq.getvalue(ids.get(), row, 0)));
  }
  config::PostgresSettings settings;
  settings.enabled = true;
  settings.connection = std::move(connection);
  outbox_ = temporaryOutbox();
  settings.outbox.folder = outbox_;
  // Never reached: write() waits long before (kMaxQueued parts are a few MB).
  settings.outbox.quotaMb = 1024;
  sink_ = std::make_unique<PostgresSink>(settings, std::move(station));
  sink_->start();
}

PostgresBatchWriter::~PostgresBatchWriter() {
  sink_->stop(0ms);
  sink_.reset();
  std::error_code ignored;
  std::filesystem::remove_all(outbox_, ignored);
}

void PostgresBatchWriter::write(const PartResult& part) {
  drainTo(kMaxQueued);
  sink_->submit(part);
}

void PostgresBatchWriter::finish() {
  drainTo(0);
  sink_->stop();
  if (const auto s = sink_->status(); s.outbox.dropped > 0 || s.outbox.writeErrors > 0)
    throw std::runtime_error("postgres " + s.peer + ": " + std::to_string(s.outbox.dropped) +
                             " parts dropped and " + std::to_string(s.outbox.writeErrors) +
                             " not queued on disk in " + outbox_.string());
}

void PostgresBatchWriter::drainTo(std::uint64_t pending) {
  auto status = sink_->status();
  auto lastProgress = std::chrono::steady_clock::now();
  auto delivered = status.delivered;
  while (status.outbox.pending > pending) {
    if (status.delivered != delivered) {
      delivered = status.delivered;
      lastProgress = std::chrono::steady_clock::now();
    } else if (std::chrono::steady_clock::now() - lastProgress > kPatience) {
      throw std::runtime_error("postgres " + status.peer + ": no part written for " +
                               std::to_string(kPatience.count()) + " s (" + status.lastError +
                               "); " + std::to_string(status.outbox.pending) + " parts unwritten");
    }
    std::this_thread::sleep_for(5ms);
    status = sink_->status();
  }
}

}  // namespace facet::service
