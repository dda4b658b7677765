// Publishing a part (Station's third stage): the PLC first, then the results store, what HTTP
// shows and the archive, then metrics and the log; and the store's retention between parts.
#include <spdlog/spdlog.h>

#include "service/daemon/part_origin.hpp"
#include "service/daemon/station.hpp"

namespace facet::service {

using Clock = std::chrono::steady_clock;

std::int64_t Station::applyRetention(std::int64_t limit) {
  std::int64_t deleted = 0;
  try {
    {
      std::lock_guard lock(storeMutex_);
      deleted = store_->applyRetention(std::chrono::system_clock::now(), limit);
    }
    if (deleted > 0) {
      metrics_.counter("facet_results_retention_deleted_total", "Parts deleted by retention")
          .increment(static_cast<double>(deleted));
      // Slices come every minute (or back to back while catching up): the metric counts them.
      spdlog::log(limit == 0 ? spdlog::level::info : spdlog::level::debug,
                  "results store: retention deleted {} parts", deleted);
    }
  } catch (const std::exception& e) {
    // Retention failing must not stop inspection; the database only keeps growing.
    spdlog::error("results store: retention failed: {}", e.what());
  }
  return deleted;
}

void Station::publishPart(Job& j) {
  PartResult& p = j.result;
  p.partId = j.partId;
  p.time = std::chrono::system_clock::now();
  recordPartOrigin(p, j.inspection ? &j.inspection->recipe() : nullptr, j.frame);
  const auto t0 = Clock::now();
  // 1. The PLC first: it is what the line waits for.
  if (plc_) plc_->publish(p, j.inspection.get(), j.error, j.trigger ? j.trigger->sequence : 0);
  // 2. The results store: a part that cannot be stored is counted and logged, never silent.
  try {
    std::lock_guard lock(storeMutex_);
    store_->store(p);
  } catch (const std::exception& e) {
    metrics_.counter("facet_store_errors_total", "Parts that could not be stored").increment();
    spdlog::error("part {} recipe {}: not stored: {}", p.partId, p.recipeId, e.what());
    std::lock_guard lock(recentMutex_);
    lastStoreError_ = e.what();
  }
  showPart(p, j.frame.image, j.overlay);
  const double publishMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  stageLatency(metrics_, "publish").observe(publishMs);
  stageLatency(metrics_, "total")
      .observe(std::chrono::duration<double, std::milli>(Clock::now() - j.acquiredAt).count());
  metrics_
      .counter("facet_parts_total", "Parts by verdict",
               std::string("verdict=\"") + verdictName(p.verdict) + "\"")
      .increment();
  metrics_.gauge("facet_queue_depth", "Items waiting per queue", "queue=\"publish\"")
      .set(static_cast<double>(publishQueue_.size()));
  if (p.verdict == Verdict::Error)
    spdlog::warn("part={} recipe={} verdict=error cause=\"{}\"", p.partId, p.recipeId, p.error);
  else
    spdlog::info("part={} recipe={} verdict={} inspect_ms={:.2f}{}", p.partId, p.recipeId,
                 verdictName(p.verdict), p.inspectionMs,
                 p.failedChecks.empty() ? "" : " failed=" + p.failedChecks.front());
  if (options_.onPart) options_.onPart(p);
}

}  // namespace facet::service
