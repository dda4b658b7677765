#pragma once
// What the HTTP server sees of a station that publishes to the fleet: the station's own view,
// with the sinks' state added to /healthz ("mqtt", "postgres"; "degraded" while a sink cannot
// reach its peer) and their gauges to /metrics. Everything else is the station's.

#include "service/daemon/metrics.hpp"
#include "service/daemon/station_view.hpp"
#include "service/sinks/fleet_publishers.hpp"

namespace facet::service {

class FleetStationView : public StationView {
 public:
  // `metrics`: the station's registry, which /metrics renders.
  FleetStationView(StationView& station, const FleetPublishers& fleet, MetricsRegistry& metrics)
      : station_(station), fleet_(fleet), metrics_(metrics) {}

  [[nodiscard]] nlohmann::json health() const override;
  [[nodiscard]] std::string metricsText() const override;
  [[nodiscard]] std::vector<PartResult> recentParts(std::size_t count) const override {
    return station_.recentParts(count);
  }
  [[nodiscard]] std::vector<PartResult> storedParts(std::uint64_t afterPartId,
                                                    std::size_t limit) const override {
    return station_.storedParts(afterPartId, limit);
  }
  [[nodiscard]] std::vector<unsigned char> lastOverlayPng() const override {
    return station_.lastOverlayPng();
  }
  [[nodiscard]] nlohmann::json summary() const override { return station_.summary(); }
  ActionOutcome selectRecipe(int recipeId) override { return station_.selectRecipe(recipeId); }
  ActionOutcome resetCounters() override { return station_.resetCounters(); }

 private:
  StationView& station_;
  const FleetPublishers& fleet_;
  MetricsRegistry& metrics_;
};

}  // namespace facet::service
