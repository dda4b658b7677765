#include "service/sinks/fleet_publishers.hpp"

namespace facet::service {

std::string FleetPublishers::stationName(const config::StationConfig& station) {
  return station.name.empty() ? station.file.stem().string() : station.name;
}

FleetPublishers::FleetPublishers(const config::StationConfig& station) {
  const std::string name = stationName(station);
  if (station.mqtt.enabled) mqtt_ = std::make_unique<MqttPublisher>(station.mqtt, name);
  if (station.postgres.enabled) postgres_ = std::make_unique<PostgresSink>(station.postgres, name);
}

void FleetPublishers::start() {
  if (mqtt_) mqtt_->start();
  if (postgres_) postgres_->start();
}

void FleetPublishers::submit(const PartResult& part) {
  if (mqtt_) mqtt_->submit(part);
  if (postgres_) postgres_->submit(part);
}

void FleetPublishers::stop(std::chrono::milliseconds flush) {
  if (mqtt_) mqtt_->stop(flush);
  if (postgres_) postgres_->stop(flush);
}

nlohmann::json FleetPublishers::health() const {
  nlohmann::json h = nlohmann::json::object();
  if (mqtt_) h["mqtt"] = mqtt_->status().toJson();
  if (postgres_) h["postgres"] = postgres_->status().toJson();
  return h;
}

bool FleetPublishers::degraded() const {
  return (mqtt_ && mqtt_->status().degraded()) || (postgres_ && postgres_->status().degraded());
}

void FleetPublishers::updateMetrics(MetricsRegistry& metrics) const {
  for (const SinkStatus& s :
       {mqtt_ ? mqtt_->status() : SinkStatus{}, postgres_ ? postgres_->status() : SinkStatus{}}) {
    if (s.name.empty()) continue;
    const std::string label = "sink=\"" + s.name + "\"";
    metrics.gauge("facet_sink_connected", "1 while the sink reaches its peer", label)
        .set(s.connected ? 1 : 0);
    metrics.gauge("facet_sink_buffered", "Results waiting in the sink's outbox on disk", label)
        .set(static_cast<double>(s.outbox.pending));
    metrics.gauge("facet_sink_delivered", "Results the peer confirmed since start", label)
        .set(static_cast<double>(s.delivered));
    metrics.gauge("facet_sink_dropped", "Oldest results dropped because the outbox was full", label)
        .set(static_cast<double>(s.outbox.dropped));
    metrics.gauge("facet_sink_write_errors", "Results the outbox could not write", label)
        .set(static_cast<double>(s.outbox.writeErrors));
  }
}

}  // namespace facet::service
