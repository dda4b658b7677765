#include <spdlog/spdlog.h>

#include "camera/image_codecs.hpp"
#include "service/daemon/part_banner.hpp"
#include "service/daemon/station.hpp"

// What a station shows over HTTP (StationView): health, metrics, recent and stored parts, the
// last picture, the summary for the dashboard, and the two actions it accepts.
namespace facet::service {

void Station::showPart(PartResult part, const cv::Mat& image, const Overlay& overlay) {
  LastPicture last;
  if (!image.empty()) {
    last.image = image;
    last.overlay = overlay;
    last.banner = partBanner(part, "part " + std::to_string(part.partId));
    last.pass = part.verdict == Verdict::Pass;
    if (archiveWriter_) archiveWriter_->submit(part, image, [last] { return last.draw(); });
  }
  const bool archiveDegraded = archive_ && archive_->degraded();
  metrics_.gauge("facet_archive_degraded", "1 while the image archive cannot write")
      .set(archiveDegraded ? 1 : 0);
  // Logged when the state changes, not per part: a full disk must not flood the journal.
  if (archiveDegraded != archiveDegradedLogged_) {
    archiveDegradedLogged_ = archiveDegraded;
    if (archiveDegraded)
      spdlog::error("archive degraded: {} (parts are still inspected and stored)",
                    archive_->lastError());
    else
      spdlog::info("archive writable again: {}", config_.archive.folder.string());
  }
  std::lock_guard lock(recentMutex_);
  ++shiftCounts_[verdictName(part.verdict)];
  recent_.push_back(std::move(part));
  while (recent_.size() > 200) recent_.pop_front();
  if (!last.image.empty()) lastPicture_ = std::move(last);
}

nlohmann::json Station::health() const {
  nlohmann::json h;
  const CameraHealth cam = camera_->health();
  h["camera"] = {{"name", camera_->name()},
                 {"connected", cam.connected},
                 {"streaming", cam.streaming},
                 {"frames", cam.frames},
                 {"incomplete_frames", cam.incomplete_frames},
                 {"reconnects", cam.reconnects},
                 {"skipped_files", cam.skipped_files},
                 {"last_error", cam.last_error}};
  // "scale only, no lens model" tells the engineer that mm come from mm_per_pixel alone.
  h["calibration"] = {{"kind", config_.calibration.kind()},
                      {"mm_per_pixel", config_.calibration.mmPerPixel},
                      {"file", config_.calibration.file ? config_.calibration.file->string() : ""}};
  bool degraded = false;
  if (plc_) {
    h["plc"] = plc_->health();
    degraded = degraded || !h["plc"]["connected"].get<bool>();
  } else {
    h["plc"] = {{"configured", false}};
  }
  {
    const auto active = recipes_.active();
    const nlohmann::json problems = recipes_.problems();
    h["recipe"] = {{"id", active->recipe().id},
                   {"name", active->recipe().name},
                   {"version", active->recipe().contentHash},
                   {"problems", problems}};
    degraded = degraded || !problems.empty();
  }
  if (archive_) {
    h["archive"] = {{"degraded", archive_->degraded()},
                    {"bytes", archive_->bytesUsed()},
                    {"last_error", archive_->lastError()}};
    degraded = degraded || archive_->degraded();
  }
  {
    std::lock_guard lock(recentMutex_);
    h["store"] = {{"file", config_.results.database.string()}, {"last_error", lastStoreError_}};
    degraded = degraded || !lastStoreError_.empty();
  }
  const bool down = !cam.connected || finished_;
  h["status"] = down ? "down" : degraded ? "degraded" : "ok";
  return h;
}

std::string Station::metricsText() const {
  auto& m = const_cast<MetricsRegistry&>(metrics_);
  const CameraHealth cam = camera_->health();
  m.gauge("facet_camera_connected", "1 while the camera is connected").set(cam.connected ? 1 : 0);
  m.gauge("facet_camera_reconnects", "Camera reconnections since start")
      .set(static_cast<double>(cam.reconnects));
  m.gauge("facet_camera_skipped_files", "Replay files refused")
      .set(static_cast<double>(cam.skipped_files));
  if (plc_) plc_->updateMetrics(m);
  return m.exposition();
}

std::vector<PartResult> Station::recentParts(std::size_t count) const {
  std::lock_guard lock(recentMutex_);
  const std::size_t n = std::min(count, recent_.size());
  return {recent_.end() - static_cast<std::ptrdiff_t>(n), recent_.end()};
}

std::vector<PartResult> Station::storedParts(std::uint64_t afterPartId, std::size_t limit) const {
  std::lock_guard lock(storeMutex_);
  return store_->partsAfter(afterPartId, limit == 0 ? 100 : limit);
}

std::vector<unsigned char> Station::lastOverlayPng() const {
  LastPicture last;
  {
    std::lock_guard lock(recentMutex_);
    last = lastPicture_;
  }
  std::vector<unsigned char> png;
  if (!last.image.empty()) encodeImage(".png", last.draw(), png);
  return png;
}

nlohmann::json Station::summary() const {
  nlohmann::json s;
  {
    std::lock_guard lock(recentMutex_);
    s["counts"] = shiftCounts_;
    nlohmann::json parts = nlohmann::json::array();
    const std::size_t n = std::min<std::size_t>(50, recent_.size());
    for (auto it = recent_.end() - static_cast<std::ptrdiff_t>(n); it != recent_.end(); ++it)
      parts.push_back(toJson(*it));
    s["recent"] = parts;
  }
  const auto active = recipes_.active();
  s["recipe"] = {{"id", active->recipe().id}, {"name", active->recipe().name}};
  nlohmann::json checks = nlohmann::json::array();
  for (const auto& step : active->recipe().steps)
    for (const auto& c : step.checks)
      checks.push_back({{"name", step.id + "." + c.name},
                        {"nominal", c.nominal},
                        {"lower", c.lower()},
                        {"upper", c.upper()},
                        {"unit", std::string(config::toString(c.unit))}});
  s["checks"] = checks;
  return s;
}

ActionOutcome Station::selectRecipe(int recipeId) {
  if (!recipes_.request(recipeId)) return {false, "no usable recipe " + std::to_string(recipeId)};
  return {true, "recipe " + std::to_string(recipeId) + " is used from the next part on"};
}

ActionOutcome Station::resetCounters() {
  std::lock_guard lock(recentMutex_);
  shiftCounts_.clear();
  return {true, "shift counters reset"};
}

}  // namespace facet::service
