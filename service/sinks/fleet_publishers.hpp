#pragma once
// The station's results sinks beyond its SQLite file, as configured in the station file's
// `mqtt` and `postgres` sections: one object the daemon starts, hands every published part to,
// asks for health and metrics, and stops. A sink that cannot reach its peer makes the station
// "degraded", never stopped: parts are still inspected, answered to the PLC and buffered.

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "config/station_config.hpp"
#include "service/daemon/metrics.hpp"
#include "service/engine/part_result.hpp"
#include "service/sinks/mqtt_publisher.hpp"
#include "service/sinks/postgres_sink.hpp"

namespace facet::service {

class FleetPublishers {
 public:
  // Opens the outboxes of the configured sinks (throws std::runtime_error naming the folder).
  explicit FleetPublishers(const config::StationConfig& station);

  [[nodiscard]] bool any() const { return mqtt_ || postgres_; }
  void start();
  // Never blocks on a peer: each sink appends the part to its outbox on disk.
  void submit(const PartResult& part);
  // Sends what is left for at most `flush` per sink, then disconnects.
  void stop(std::chrono::milliseconds flush);

  // {"mqtt": {...}, "postgres": {...}} for the sinks that are configured.
  [[nodiscard]] nlohmann::json health() const;
  [[nodiscard]] bool degraded() const;
  // facet_sink_connected, facet_sink_buffered, facet_sink_dropped_total, ... per sink.
  void updateMetrics(MetricsRegistry& metrics) const;

  // The station name used in topics and rows: `name`, else the station file's stem.
  static std::string stationName(const config::StationConfig& station);

 private:
  std::unique_ptr<MqttPublisher> mqtt_;
  std::unique_ptr<PostgresSink> postgres_;
};

}  // namespace facet::service
