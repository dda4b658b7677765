#pragma once
// PlcPublisher: the station's side of the PLC link. It builds the register map (the station's
// handshake plus every recipe's outputs), writes each part's result to it, and reports the
// link's state for /healthz and /metrics. The handshake itself is plc/plc_link.hpp.

#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/recipe.hpp"
#include "config/station_config.hpp"
#include "plc/plc_link.hpp"
#include "service/daemon/metrics.hpp"
#include "service/daemon/part_error.hpp"
#include "service/engine/inspect_part.hpp"
#include "service/engine/part_result.hpp"

namespace facet::service {

class PlcPublisher {
 public:
  // Throws std::invalid_argument when the register map is invalid (see PlcLink).
  PlcPublisher(const config::StationConfig& station,
               const std::vector<std::shared_ptr<const config::Recipe>>& recipes,
               MetricsRegistry& metrics);

  [[nodiscard]] plc::PlcLink& link() { return link_; }
  [[nodiscard]] const plc::PlcLink& link() const { return link_; }

  // Writes the part's verdict and values. `recipe` (null for a part no recipe was chosen for)
  // says which outputs are this part's: those it did not measure are written as "not measured"
  // (NaN / 0), so that the PLC never reads the previous part's values as this part's.
  void publish(const PartResult& part, const PreparedRecipe* recipe, PartError error,
               std::uint64_t triggerSequence);

  [[nodiscard]] nlohmann::json health() const;
  void updateMetrics(MetricsRegistry& metrics) const;

 private:
  MetricsRegistry& metrics_;
  plc::PlcLink link_;
};

}  // namespace facet::service
