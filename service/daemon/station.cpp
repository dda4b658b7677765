#include "service/daemon/station.hpp"

#include <cmath>
#include <limits>

#include <spdlog/spdlog.h>

#include <opencv2/imgcodecs.hpp>

#include "algorithms/scan/scan_file.hpp"
#include "camera/camera_factory.hpp"
#include "camera/sidecar_metadata.hpp"
#include "service/daemon/part_origin.hpp"

namespace facet::service {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// How long a stopping station waits for a connected PLC to take the results still queued.
constexpr std::chrono::milliseconds kPlcFlushTimeout{2000};

struct Station::Job {
  std::uint64_t partId = 0;
  Frame frame;
  std::optional<plc::TriggerEvent> trigger;
  std::optional<scan::Scan> scan;  // scan recipes
  std::shared_ptr<const RecipeInspection> inspection;
  Clock::time_point acquiredAt;
  Clock::time_point inspectedAt;
  PartResult result;
  PartError error = PartError::None;  // set for a part that was not inspected
  Overlay overlay;
};

namespace {

std::int64_t nowTicks() {
  return Clock::now().time_since_epoch().count();
}

double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

ArchivePolicy archivePolicy(const config::ArchiveSettings& a) {
  ArchivePolicy p;
  p.folder = a.folder;
  p.quotaBytes = static_cast<std::uint64_t>(a.quotaMb * 1024 * 1024);
  p.failed = a.keep != config::ArchiveSettings::Keep::None;
  p.goodEvery = a.keep == config::ArchiveSettings::Keep::All ? 1 : 0;
  return p;
}

// The station's register map plus every recipe's outputs.
plc::RegisterMap fullRegisterMap(
    const config::StationConfig& station,
    const std::vector<std::shared_ptr<const config::Recipe>>& recipes) {
  plc::RegisterMap map = station.registerMap;
  for (const auto& recipe : recipes)
    for (const auto& [check, step] : recipe->plcOutputs())
      map.results.push_back(check->plc->output);
  return map;
}

// A recipe whose every step works on range scans needs no camera frame.
bool scanOnly(const config::Recipe& recipe) {
  return !recipe.steps.empty() &&
         std::all_of(recipe.steps.begin(), recipe.steps.end(),
                     [](const auto& s) { return s.kind == config::StepKind::ScanAlign; });
}

RetentionPolicy retentionPolicy(const config::ResultsStoreSettings& s) {
  RetentionPolicy r;
  if (s.keepDays > 0)
    r.maxAge = std::chrono::seconds(static_cast<std::int64_t>(std::llround(s.keepDays * 86400)));
  if (s.keepParts > 0) r.maxParts = s.keepParts;
  return r;
}

}  // namespace

Station::Station(config::StationConfig config, StationOptions options)
    : config_(std::move(config)),
      options_(std::move(options)),
      library_(config_.recipeLoadOptions()),
      inspectQueue_(options_.inspectQueue, options_.overflow),
      publishQueue_(options_.publishQueue, OverflowPolicy::Block) {
  store_ =
      std::make_unique<ResultsStore>(config_.results.database, retentionPolicy(config_.results));
  applyRetention(0);  // a large first clean-up happens here, before READY, not between parts
  nextPartId_ = store_->lastPartId() + 1;
  firstPartId_ = nextPartId_;
  if (!config_.archive.folder.empty())
    archive_ = std::make_unique<ImageArchive>(archivePolicy(config_.archive));

  const auto report = library_.reload();
  for (const auto& d : report.diagnostics.items()) spdlog::error("recipe: {}", config::format(d));
  const auto recipes = library_.recipes();
  if (recipes.empty())
    throw std::runtime_error("no usable recipe in " + config_.recipesFolder.string() +
                             (report.diagnostics.empty() ? "" : ":\n" + report.diagnostics.text()));
  const int first = options_.recipe.value_or(recipes.front()->id);
  std::string error;
  active_ = inspectionFor(first, &error);
  if (!active_) throw std::runtime_error("recipe " + std::to_string(first) + ": " + error);

  // Every recorded file is a part: one the replay cannot read is answered "not inspected".
  config_.camera.replay.report_unreadable = true;
  camera_ = makeCamera(config_.camera);
  if (!config_.camera.scans.folder.empty()) scans_ = makeScanReplay(config_.camera.scans);
  if (options_.usePlc && !config_.hasPlc)
    spdlog::info("station {}: no plc section, running without a PLC link", config_.file.string());
  if (options_.usePlc && config_.hasPlc)
    plc_ = std::make_unique<plc::PlcLink>(fullRegisterMap(config_, recipes), config_.plc);
  metrics_.gauge("facet_up", "1 while facetd runs").set(1);
}

Station::~Station() {
  requestStop();
  join();
}

std::shared_ptr<const RecipeInspection> Station::inspectionFor(int recipeId, std::string* error) {
  std::lock_guard lock(recipeMutex_);
  const auto recipe = library_.find(recipeId);
  if (!recipe) {
    *error = "no such recipe";
    return nullptr;
  }
  auto& cached = inspections_[recipeId];
  if (cached && cached->recipePtr() == recipe) return cached;
  try {
    cached = std::make_shared<RecipeInspection>(recipe, config_.calibration.mmPerPixel);
    recipeErrors_.erase(recipeId);
    return cached;
  } catch (const std::exception& e) {
    *error = e.what();
    recipeErrors_[recipeId] = e.what();
    spdlog::error("recipe {}: {}", recipeId, e.what());
    // A recipe whose resources broke keeps running in its last good preparation, if any.
    return cached;
  }
}

void Station::start() {
  camera_->open();
  camera_->start();
  if (plc_) {
    plc_->start();
    plc_->setActiveRecipe(active_->recipe().id);
    plc_->setReady(true);
  }
  const auto beat = nowTicks();
  acquisitionBeat_ = beat;
  inspectionBeat_ = beat;
  acquisition_ = std::thread([this] { acquisitionLoop(); });
  inspection_ = std::thread([this] { inspectionLoop(); });
  publishing_ = std::thread([this] { publishingLoop(); });
  spdlog::info("station {} running: camera {}, recipe {} '{}', PLC {}", config_.name,
               camera_->name(), active_->recipe().id, active_->recipe().name,
               plc_ ? config_.plc.host + ":" + std::to_string(config_.plc.port) : "none");
}

void Station::requestStop() {
  stopRequested_ = true;
}

void Station::join() {
  if (acquisition_.joinable()) acquisition_.join();
  if (inspection_.joinable()) inspection_.join();
  if (publishing_.joinable()) publishing_.join();
  if (plc_) {
    // The last parts were published a moment ago: let a connected PLC take them before the
    // link goes (what is still queued after this is logged part by part as undelivered).
    plc_->flush(kPlcFlushTimeout);
    plc_->setReady(false);
    plc_->stop();
  }
  if (camera_) {
    try {
      camera_->stop();
      camera_->close();
    } catch (const std::exception& e) {
      spdlog::warn("camera: {}", e.what());
    }
  }
  finished_ = true;
}

bool Station::loopsAlive(std::chrono::milliseconds within) const {
  const auto limit = std::chrono::duration_cast<Clock::duration>(within).count();
  const auto now = nowTicks();
  return now - acquisitionBeat_.load() < limit && now - inspectionBeat_.load() < limit;
}

std::shared_ptr<const RecipeInspection> Station::recipeForPart(const Frame* frame,
                                                               const plc::TriggerEvent* trigger) {
  // Which recipe the part is inspected with, decided once per part, before inspection starts:
  // a recorded frame's own recipe (replay regression), else the PLC's recipe select at the
  // trigger, else a switch asked over HTTP, else the recipe in use.
  std::optional<int> wanted;
  if (frame) {
    if (auto it = frame->metadata.find("recipe"); it != frame->metadata.end()) {
      try {
        wanted = std::stoi(it->second);
      } catch (const std::exception&) {
        spdlog::warn("{}: sidecar recipe '{}' is not a number", frame->source, it->second);
      }
    }
  }
  if (!wanted && trigger && trigger->recipe > 0) wanted = trigger->recipe;
  {
    std::lock_guard lock(recipeMutex_);
    if (!wanted && requestedRecipe_) wanted = requestedRecipe_;
    requestedRecipe_.reset();
    if (!wanted || *wanted == active_->recipe().id) {
      // Same recipe: pick up a reloaded version of it, if any.
      wanted = active_->recipe().id;
    }
  }
  const auto t0 = Clock::now();
  std::string error;
  auto next = inspectionFor(*wanted, &error);
  std::lock_guard lock(recipeMutex_);
  if (!next) {
    spdlog::error("recipe {} requested but not usable ({}); staying with {}", *wanted, error,
                  active_->recipe().id);
    metrics_.counter("facet_recipe_switch_failures_total", "Recipe switches refused").increment();
    return active_;
  }
  if (next != active_) {
    const bool switched = next->recipe().id != active_->recipe().id;
    active_ = next;
    if (switched) {
      const double ms = msSince(t0);
      metrics_.counter("facet_recipe_switches_total", "Recipe switches between parts").increment();
      metrics_.gauge("facet_recipe_switch_ms", "Duration of the last recipe switch").set(ms);
      spdlog::info("recipe switched to {} '{}' in {:.2f} ms", next->recipe().id,
                   next->recipe().name, ms);
      if (plc_) plc_->setActiveRecipe(next->recipe().id);
    }
  }
  return active_;
}

void Station::acquisitionLoop() {
  const bool triggered = plc_ && plc_->settings().mode == plc::HandshakeMode::Triggered;
  bool endOfStream = false;
  while (!stopRequested_) {
    acquisitionBeat_ = nowTicks();
    if (options_.maxParts > 0 && partsTaken_ >= options_.maxParts) break;
    std::optional<plc::TriggerEvent> trigger;
    if (triggered) {
      trigger = plc_->waitTrigger(100ms);
      if (!trigger) continue;
      // Trigger edge read by the link -> taken here (busy written, queue hand-over).
      metrics_
          .histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(), "stage=\"trigger\"")
          .observe(
              std::chrono::duration<double, std::milli>(Clock::now() - trigger->seenAt).count());
      camera_->softwareTrigger();
    }
    const auto t0 = Clock::now();
    auto job = std::make_unique<Job>();
    job->trigger = trigger;
    job->acquiredAt = t0;
    if (scans_ && scanOnly(recipeForPart(nullptr, trigger ? &*trigger : nullptr)->recipe())) {
      if (!acquireScan(*job)) {
        if (options_.stopAtEndOfStream && scansEnded_) {
          // The recorded scans are all used: a trigger now gets a not-inspected answer, and the
          // replay ends.
          if (trigger) {
            takePart(*job);
            publishNotInspected(std::move(*job), PartError::NoInput,
                                "no range scan left for the trigger");
          }
          break;
        }
        if (trigger) {
          takePart(*job);
          publishNotInspected(std::move(*job), PartError::NoInput, "no range scan for the trigger");
          continue;
        }
        if (options_.stopAtEndOfStream) break;
        std::this_thread::sleep_for(50ms);
        continue;
      }
      takePart(*job);
      inspectQueue_.push(std::move(job));
      continue;
    }
    // Free run: a camera set to software trigger is triggered by the station itself, one frame
    // per part (ignored by free-running cameras).
    if (!triggered) camera_->softwareTrigger();
    GrabResult grab = camera_->grab(triggered ? 2000ms : 200ms);
    switch (grab.status) {
      case GrabStatus::Ok:
        break;
      case GrabStatus::Timeout:
        if (!trigger) continue;
        takePart(*job);
        publishNotInspected(std::move(*job), PartError::NoFrame,
                            "no frame within 2 s of the trigger");
        continue;
      case GrabStatus::Incomplete:
        metrics_.counter("facet_incomplete_frames_total", "Frames with missing pixel data")
            .increment();
        job->frame = std::move(grab.frame);
        takePart(*job);
        publishNotInspected(std::move(*job), PartError::IncompleteFrame,
                            "incomplete frame: " + grab.message);
        continue;
      case GrabStatus::EndOfStream:
        endOfStream = true;
        break;
      case GrabStatus::Error:
        if (!grab.frame.source.empty()) {
          // A recorded file the replay refused (truncated, empty, not an image, oversized): a
          // part that was not inspected, stored under its file name, never skipped silently.
          metrics_.counter("facet_refused_files_total", "Replay files refused as not inspected")
              .increment();
          job->frame = std::move(grab.frame);
          takePart(*job);
          publishNotInspected(std::move(*job), PartError::NoInput,
                              "not inspected: " + grab.message);
          continue;
        }
        [[fallthrough]];
      case GrabStatus::Disconnected:
      case GrabStatus::NotStarted:
        metrics_.counter("facet_camera_errors_total", "Grabs that failed").increment();
        spdlog::warn("camera: {}: {}", toString(grab.status), grab.message);
        if (trigger) {
          takePart(*job);
          publishNotInspected(std::move(*job), PartError::CameraUnavailable,
                              std::string("camera ") + toString(grab.status) + ": " + grab.message);
        }
        std::this_thread::sleep_for(100ms);
        continue;
    }
    if (endOfStream) {
      if (trigger) {
        // Every accepted trigger gets an answer, even when the replay has nothing left.
        takePart(*job);
        publishNotInspected(std::move(*job), PartError::NoInput,
                            "replay finished: no image left for the trigger");
      }
      if (options_.stopAtEndOfStream) break;
      std::this_thread::sleep_for(50ms);
      continue;
    }
    metrics_.histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(), "stage=\"grab\"")
        .observe(msSince(t0));
    job->frame = std::move(grab.frame);
    takePart(*job);
    if (auto dropped = inspectQueue_.push(std::move(job)); dropped && *dropped) {
      metrics_.counter("facet_missed_parts_total", "Parts not inspected: inspection fell behind")
          .increment();
      publishNotInspected(std::move(**dropped), PartError::Missed,
                          "missed: inspection fell behind");
    }
    metrics_.gauge("facet_queue_depth", "Items waiting per queue", "queue=\"inspect\"")
        .set(static_cast<double>(inspectQueue_.size()));
  }
  inspectQueue_.close();
}

bool Station::acquireScan(Job& job) {
  ScanResult next = scans_->next();
  if (next.status == GrabStatus::EndOfStream) {
    scansEnded_ = true;
    return false;
  }
  if (!next) {
    spdlog::error("scan replay: {}", next.message);
    return false;
  }
  job.frame.id = next.scan.id;
  job.frame.source = next.scan.source;
  job.frame.metadata = next.scan.metadata;
  // Serial and expected verdict come from the scan file's sidecar, as for images.
  // CARMEN scans are named "file:line"; CSV scans by their file.
  std::string source = next.scan.source;
  if (const auto colon = source.rfind(':');
      colon != std::string::npos && colon + 1 < source.size() &&
      source.find_first_not_of("0123456789", colon + 1) == std::string::npos)
    source.resize(colon);
  const std::filesystem::path file = source;
  try {
    for (auto& [key, value] : SidecarMetadata::loadFolder(file.parent_path()).forImage(file))
      job.frame.metadata.emplace(key, value);
  } catch (const std::exception& e) {
    spdlog::warn("{}: {}", file.string(), e.what());
  }
  job.scan = std::move(next.scan.scan);
  return true;
}

void Station::inspectionLoop() {
  while (true) {
    inspectionBeat_ = nowTicks();
    auto job = inspectQueue_.pop(100ms);
    if (!job) {
      if (inspectQueue_.closed() && inspectQueue_.size() == 0) break;
      continue;
    }
    Job& j = **job;
    spdlog::debug("part={} inspecting {}", j.partId, j.frame.source);
    InspectionInput input;
    input.image = j.frame.image;
    input.scan = j.scan;
    if (auto it = j.frame.metadata.find("scan"); !input.scan && it != j.frame.metadata.end()) {
      // A recorded frame may carry the range scan taken with it (scan recipes).
      const auto path = std::filesystem::path(j.frame.source).parent_path() / it->second;
      try {
        input.scan = scan::readScanCsvFile(path.string());
      } catch (const std::exception& e) {
        spdlog::error("part {}: scan {}: {}", j.partId, path.string(), e.what());
      }
    }
    const InspectionOutcome outcome = j.inspection->inspect(input);
    j.inspectedAt = Clock::now();
    PartResult& p = j.result;
    recordOutcome(p, outcome);
    j.overlay = outcome.overlay;
    metrics_
        .histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(), "stage=\"inspect\"")
        .observe(outcome.totalMs);
    publishQueue_.push(std::move(*job));
  }
  publishQueue_.close();
}

void Station::takePart(Job& job) {
  job.partId = nextPartId_++;
  ++partsTaken_;
  job.inspection = recipeForPart(&job.frame, job.trigger ? &*job.trigger : nullptr);
}

void Station::publishNotInspected(Job job, PartError code, const std::string& cause) {
  job.error = code;
  job.result.verdict = Verdict::Error;
  job.result.error = cause;
  job.inspectedAt = Clock::now();
  publishQueue_.push(std::make_unique<Job>(std::move(job)));
}

void Station::publishingLoop() {
  // Parts are published strictly in part-id order: a part that was not inspected (missed,
  // incomplete frame) skips the inspection stage and must not overtake the parts before it.
  // Every id the acquisition takes reaches this stage exactly once, so waiting is bounded.
  std::map<std::uint64_t, std::unique_ptr<Job>> waiting;
  std::uint64_t next = firstPartId_;
  auto publishReady = [&](bool all) {
    while (!waiting.empty() && (all || waiting.begin()->first == next)) {
      auto job = std::move(waiting.begin()->second);
      waiting.erase(waiting.begin());
      next = job->partId + 1;
      publishPart(*job);
    }
  };
  auto nextRetention = Clock::now() + kRetentionPeriod;
  while (true) {
    if (Clock::now() >= nextRetention) {
      // A full slice means more is due: the next slice after the next part (or 100 ms).
      const bool more = applyRetention(kRetentionSlice) >= kRetentionSlice;
      nextRetention = more ? Clock::now() : Clock::now() + kRetentionPeriod;
    }
    auto job = publishQueue_.pop(100ms);
    if (!job) {
      if (publishQueue_.closed() && publishQueue_.size() == 0) break;
      continue;
    }
    const std::uint64_t id = (*job)->partId;
    waiting.emplace(id, std::move(*job));
    publishReady(false);
  }
  publishReady(true);
  drained_ = true;
}

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
  if (plc_) {
    plc::InspectionResult r;
    r.partId = std::to_string(p.partId);
    r.pass = p.verdict == Verdict::Pass;
    for (const auto& m : p.measurements) r.values[m.name] = m.value;
    // This recipe's outputs that were not measured (a part not inspected, a failed step) are
    // written as "not measured" (NaN / 0): the PLC must not read the previous part's values as
    // this part's. Other recipes' outputs keep their registers (onlyGivenValues).
    if (j.inspection)
      for (const auto& [check, step] : j.inspection->recipe().plcOutputs())
        r.values.try_emplace(check->plc->output.name, std::numeric_limits<double>::quiet_NaN());
    r.onlyGivenValues = true;  // other recipes' outputs keep their registers
    if (p.verdict == Verdict::Error)
      r.errorCode =
          static_cast<int>(j.error == PartError::None ? PartError::InspectionFailed : j.error);
    r.triggerSequence = j.trigger ? j.trigger->sequence : 0;
    if (!plc_->publish(std::move(r)))
      spdlog::error("part {} recipe {}: result not delivered to the PLC (queue full)", p.partId,
                    p.recipeId);
    // Handshakes completed so far (the link times each once the PLC has acknowledged it).
    for (const auto& t : plc_->takeTimings())
      metrics_
          .histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(),
                     "stage=\"plc_write\"")
          .observe(std::chrono::duration<double, std::milli>(t.publishToResultValid).count());
  }
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
  publish(p, j.frame.image, j.overlay);
  const double publishMs = msSince(t0);
  metrics_.histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(), "stage=\"publish\"")
      .observe(publishMs);
  metrics_.histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(), "stage=\"total\"")
      .observe(msSince(j.acquiredAt));
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

void Station::publish(PartResult part, const cv::Mat& image, const Overlay& overlay) {
  LastPicture last;
  if (!image.empty()) {
    last.image = image;
    last.overlay = overlay;
    last.banner = "part " + std::to_string(part.partId) + "  " + verdictName(part.verdict);
    if (!part.failedChecks.empty()) last.banner += "  " + part.failedChecks.front();
    if (part.verdict == Verdict::Error) last.banner += "  " + part.error;
    last.pass = part.verdict == Verdict::Pass;
    if (archive_) archive_->archive(part, image, [&last] { return last.draw(); });
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

config::ReloadReport Station::reloadRecipes() {
  auto report = library_.reload();
  for (const auto& d : report.diagnostics.items()) spdlog::error("recipe: {}", config::format(d));
  for (int id : report.loaded) {
    std::string error;
    if (inspectionFor(id, &error)) spdlog::info("recipe {} reloaded", id);
  }
  metrics_.counter("facet_recipe_reloads_total", "Recipe folder reloads").increment();
  return report;
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
    const auto s = plc_->stats();
    h["plc"] = {{"connected", s.connected},
                {"queue_depth", s.queueDepth},
                {"dropped", s.dropped},
                {"missed_triggers", s.missedTriggers},
                {"connection_losses", s.connectionLosses},
                {"modbus_errors", s.modbusErrors}};
    degraded = degraded || !s.connected;
  } else {
    h["plc"] = {{"configured", false}};
  }
  {
    std::lock_guard lock(recipeMutex_);
    nlohmann::json problems = nlohmann::json::array();
    const config::Diagnostics rejected = library_.problems();
    for (const auto& d : rejected.items()) problems.push_back(config::format(d));
    for (const auto& [id, e] : recipeErrors_)
      problems.push_back("recipe " + std::to_string(id) + ": " + e);
    h["recipe"] = {{"id", active_->recipe().id},
                   {"name", active_->recipe().name},
                   {"version", active_->recipe().contentHash},
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
  if (plc_) {
    const auto s = plc_->stats();
    m.gauge("facet_plc_connected", "1 while the PLC link is up").set(s.connected ? 1 : 0);
    m.gauge("facet_plc_reconnects", "PLC connects since start")
        .set(static_cast<double>(s.connects));
    m.gauge("facet_plc_dropped_results", "Results the PLC queue dropped")
        .set(static_cast<double>(s.dropped));
    m.gauge("facet_plc_missed_triggers", "Triggers raised while busy")
        .set(static_cast<double>(s.missedTriggers));
    m.gauge("facet_queue_depth", "Items waiting per queue", "queue=\"plc\"")
        .set(static_cast<double>(s.queueDepth));
  }
  return m.exposition();
}

std::vector<PartResult> Station::recentParts(std::size_t count) const {
  std::lock_guard lock(recentMutex_);
  const std::size_t n = std::min(count, recent_.size());
  return {recent_.end() - static_cast<std::ptrdiff_t>(n), recent_.end()};
}

std::vector<PartResult> Station::storedParts(std::uint64_t afterPartId, std::size_t limit) const {
  std::lock_guard lock(storeMutex_);
  auto parts = store_->latest(limit == 0 ? 100 : limit);
  std::erase_if(parts, [&](const PartResult& p) { return p.partId <= afterPartId; });
  return parts;
}

std::vector<unsigned char> Station::lastOverlayPng() const {
  LastPicture last;
  {
    std::lock_guard lock(recentMutex_);
    last = lastPicture_;
  }
  std::vector<unsigned char> png;
  if (!last.image.empty()) cv::imencode(".png", last.draw(), png);
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
  std::lock_guard lock(recipeMutex_);
  s["recipe"] = {{"id", active_->recipe().id}, {"name", active_->recipe().name}};
  nlohmann::json checks = nlohmann::json::array();
  for (const auto& step : active_->recipe().steps)
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
  if (!library_.find(recipeId)) return {false, "no usable recipe " + std::to_string(recipeId)};
  std::lock_guard lock(recipeMutex_);
  requestedRecipe_ = recipeId;
  return {true, "recipe " + std::to_string(recipeId) + " is used from the next part on"};
}

ActionOutcome Station::resetCounters() {
  std::lock_guard lock(recentMutex_);
  shiftCounts_.clear();
  return {true, "shift counters reset"};
}

}  // namespace facet::service
