#pragma once
// What the HTTP server may see of and ask from a running station. The daemon implements it; the
// HTTP layer never touches the pipeline's internals.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "service/engine/part_result.hpp"

namespace facet::service {

struct ActionOutcome {
  bool ok = false;
  std::string message;
};

class StationView {
 public:
  virtual ~StationView() = default;
  // {"status": "ok"|"degraded"|"down", "camera": {...}, "plc": {...}, "recipe": {...}, ...}
  [[nodiscard]] virtual nlohmann::json health() const = 0;
  [[nodiscard]] virtual std::string metricsText() const = 0;
  // The newest `count` parts, newest last (from memory, not the database).
  [[nodiscard]] virtual std::vector<PartResult> recentParts(std::size_t count) const = 0;
  // Parts with id > afterPartId from the results store, oldest first, at most `limit`.
  [[nodiscard]] virtual std::vector<PartResult> storedParts(std::uint64_t afterPartId,
                                                            std::size_t limit) const = 0;
  // The last inspected image with overlays, PNG-encoded (empty before the first part).
  [[nodiscard]] virtual std::vector<unsigned char> lastOverlayPng() const = 0;
  // Shift counters and the recipe in use, for the dashboard.
  [[nodiscard]] virtual nlohmann::json summary() const = 0;

  virtual ActionOutcome selectRecipe(int recipeId) = 0;
  virtual ActionOutcome resetCounters() = 0;
};

}  // namespace facet::service
