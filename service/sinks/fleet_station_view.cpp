#include "service/sinks/fleet_station_view.hpp"

namespace facet::service {

nlohmann::json FleetStationView::health() const {
  nlohmann::json h = station_.health();
  h.update(fleet_.health());  // adds "mqtt" and "postgres"
  // A sink that cannot deliver degrades the station (parts are still inspected and buffered);
  // it never makes it "down".
  if (fleet_.degraded() && h.value("status", "") == "ok") h["status"] = "degraded";
  return h;
}

std::string FleetStationView::metricsText() const {
  fleet_.updateMetrics(metrics_);
  return station_.metricsText();
}

}  // namespace facet::service
