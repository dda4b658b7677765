#pragma once
// What a results sink (MQTT, PostgreSQL) reports to /healthz and /metrics.

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "service/sinks/outbox.hpp"

namespace facet::service {

struct SinkStatus {
  std::string name;  // "mqtt", "postgres"
  std::string peer;  // broker host:port, or the database's host/port/dbname
  bool connected = false;
  std::string lastError;        // why it is not connected (empty while connected)
  std::uint64_t delivered = 0;  // parts the peer confirmed since start
  std::uint64_t connects = 0;   // successful connections since start
  OutboxStats outbox;

  // Not connected: results wait in the outbox; the station still inspects and answers the PLC.
  [[nodiscard]] bool degraded() const { return !connected; }
  [[nodiscard]] nlohmann::json toJson() const {
    return {{"peer", peer},
            {"connected", connected},
            {"last_error", lastError},
            {"delivered", delivered},
            {"connects", connects},
            {"buffered", outbox.pending},
            {"buffered_bytes", outbox.bytes},
            {"dropped", outbox.dropped},
            {"write_errors", outbox.writeErrors},
            {"recovered_at_start", outbox.recovered}};
  }
};

}  // namespace facet::service
