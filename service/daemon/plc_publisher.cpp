#include "service/daemon/plc_publisher.hpp"

#include <limits>

#include <spdlog/spdlog.h>

namespace facet::service {
namespace {

plc::RegisterMap fullRegisterMap(
    const config::StationConfig& station,
    const std::vector<std::shared_ptr<const config::Recipe>>& recipes) {
  plc::RegisterMap map = station.registerMap;
  for (const auto& recipe : recipes)
    for (const auto& [check, step] : recipe->plcOutputs())
      map.results.push_back(check->plc->output);
  return map;
}

}  // namespace

PlcPublisher::PlcPublisher(const config::StationConfig& station,
                           const std::vector<std::shared_ptr<const config::Recipe>>& recipes,
                           MetricsRegistry& metrics)
    : metrics_(metrics), link_(fullRegisterMap(station, recipes), station.plc) {}

void PlcPublisher::publish(const PartResult& p, const PreparedRecipe* recipe, PartError error,
                           std::uint64_t triggerSequence) {
  plc::InspectionResult r;
  r.partId = std::to_string(p.partId);
  r.pass = p.verdict == Verdict::Pass;
  for (const auto& m : p.measurements) r.values[m.name] = m.value;
  if (recipe)
    for (const auto& [check, step] : recipe->recipe().plcOutputs())
      r.values.try_emplace(check->plc->output.name, std::numeric_limits<double>::quiet_NaN());
  r.onlyGivenValues = true;  // other recipes' outputs keep their registers
  if (p.verdict == Verdict::Error)
    r.errorCode = static_cast<int>(error == PartError::None ? PartError::InspectionFailed : error);
  r.triggerSequence = triggerSequence;
  if (!link_.publish(std::move(r)))
    spdlog::error("part {} recipe {}: result not delivered to the PLC (queue full)", p.partId,
                  p.recipeId);
  // Handshakes completed so far (the link times each once the PLC has acknowledged it).
  for (const auto& t : link_.takeTimings())
    stageLatency(metrics_, "plc_write")
        .observe(std::chrono::duration<double, std::milli>(t.publishToResultValid).count());
}

nlohmann::json PlcPublisher::health() const {
  const auto s = link_.stats();
  return {{"connected", s.connected},
          {"queue_depth", s.queueDepth},
          {"dropped", s.dropped},
          {"missed_triggers", s.missedTriggers},
          {"connection_losses", s.connectionLosses},
          {"modbus_errors", s.modbusErrors}};
}

void PlcPublisher::updateMetrics(MetricsRegistry& m) const {
  const auto s = link_.stats();
  m.gauge("facet_plc_connected", "1 while the PLC link is up").set(s.connected ? 1 : 0);
  m.gauge("facet_plc_reconnects", "PLC connects since start").set(static_cast<double>(s.connects));
  m.gauge("facet_plc_dropped_results", "Results the PLC queue dropped")
      .set(static_cast<double>(s.dropped));
  m.gauge("facet_plc_missed_triggers", "Triggers raised while busy")
      .set(static_cast<double>(s.missedTriggers));
  m.gauge("facet_queue_depth", "Items waiting per queue", "queue=\"plc\"")
      .set(static_cast<double>(s.queueDepth));
}

}  // namespace facet::service
