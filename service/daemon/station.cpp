#include "service/daemon/station.hpp"

#include <cmath>

#include <spdlog/spdlog.h>

#include "camera/camera_factory.hpp"
#include "service/daemon/part_origin.hpp"
#include "service/daemon/recorded_scans.hpp"
#include "service/engine/warm_up.hpp"

namespace facet::service {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// How long a stopping station waits for a connected PLC to take the results still queued.
constexpr std::chrono::milliseconds kPlcFlushTimeout{2000};

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

RetentionPolicy retentionPolicy(const config::ResultsStoreSettings& s) {
  RetentionPolicy r;
  if (s.keepDays > 0)
    r.maxAge = std::chrono::seconds(static_cast<std::int64_t>(std::llround(s.keepDays * 86400)));
  if (s.keepParts > 0) r.maxParts = s.keepParts;
  return r;
}

}  // namespace

Station::Station(config::StationConfig config, const config::StepKindRegistry& kinds,
                 StationOptions options)
    : config_(std::move(config)),
      options_(std::move(options)),
      store_(std::make_unique<ResultsStore>(config_.results.database,
                                            retentionPolicy(config_.results))),
      recipes_(config_, kinds, options_.recipe, metrics_),
      inspectQueue_(options_.inspectQueue, options_.overflow),
      publishQueue_(options_.publishQueue, OverflowPolicy::Block) {
  applyRetention(0);  // a large first clean-up happens here, before READY, not between parts
  nextPartId_ = store_->lastPartId() + 1;
  firstPartId_ = nextPartId_;
  if (!config_.archive.folder.empty()) {
    archive_ = std::make_unique<ImageArchive>(archivePolicy(config_.archive));
    archiveWriter_ = std::make_unique<ArchiveWriter>(*archive_, metrics_, kArchiveQueue);
  }
  // Every recorded file is a part: one the replay cannot read is answered "not inspected".
  config_.camera.replay.report_unreadable = true;
  camera_ = makeCamera(config_.camera);
  if (!config_.camera.scans.folder.empty()) scans_ = makeScanReplay(config_.camera.scans);
  if (options_.usePlc && !config_.hasPlc)
    spdlog::info("station {}: no plc section, running without a PLC link", config_.file.string());
  if (options_.usePlc && config_.hasPlc) {
    plc_ = std::make_unique<PlcPublisher>(config_, recipes_.recipes(), metrics_);
    recipes_.onSwitch([this](int id) { plc_->link().setActiveRecipe(id); });
  }
  metrics_.gauge("facet_up", "1 while facetd runs").set(1);
}

Station::~Station() {
  requestStop();
  join();
}

void Station::start() {
  camera_->open();
  camera_->start();
  if (plc_) {
    plc_->link().start();
    plc_->link().setActiveRecipe(recipes_.active()->recipe().id);
  }
  const auto beat = nowTicks();
  acquisitionBeat_ = beat;
  inspectionBeat_ = beat;
  inspection_ = std::thread([this] { inspectionLoop(); });
  warmedUp_.wait();  // the PLC sees the station ready once the first part costs no more
  if (plc_) plc_->link().setReady(true);
  acquisition_ = std::thread([this] { acquisitionLoop(); });
  publishing_ = std::thread([this] { publishingLoop(); });
  spdlog::info("station {} running: camera {}, recipe {} '{}', PLC {}", config_.name,
               camera_->name(), recipes_.active()->recipe().id, recipes_.active()->recipe().name,
               plc_ ? config_.plc.host + ":" + std::to_string(config_.plc.port) : "none");
}

void Station::requestStop() {
  stopRequested_ = true;
}

void Station::join() {
  if (acquisition_.joinable()) acquisition_.join();
  if (inspection_.joinable()) inspection_.join();
  if (publishing_.joinable()) publishing_.join();
  if (archiveWriter_) archiveWriter_->flush();  // the last parts' pictures are on disk
  if (plc_) {
    // The last parts were published a moment ago: let a connected PLC take them before the
    // link goes (what is still queued after this is logged part by part as undelivered).
    plc_->link().flush(kPlcFlushTimeout);
    plc_->link().setReady(false);
    plc_->link().stop();
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

void Station::acquisitionLoop() {
  const bool triggered = plc_ && plc_->link().settings().mode == plc::HandshakeMode::Triggered;
  bool endOfStream = false;
  while (!stopRequested_) {
    acquisitionBeat_ = nowTicks();
    if (options_.maxParts > 0 && partsTaken_ >= options_.maxParts) break;
    std::optional<plc::TriggerEvent> trigger;
    if (triggered) {
      trigger = plc_->link().waitTrigger(100ms);
      if (!trigger) continue;
      // Trigger edge read by the link -> taken here (busy written, queue hand-over).
      stageLatency(metrics_, "trigger")
          .observe(
              std::chrono::duration<double, std::milli>(Clock::now() - trigger->seenAt).count());
      camera_->softwareTrigger();
    }
    const auto t0 = Clock::now();
    auto job = std::make_unique<Job>(Job{.trigger = trigger, .acquiredAt = t0});
    if (scans_ && !recipes_.peek(trigger ? &*trigger : nullptr)->needsImage) {
      if (!acquireScan(*job)) {
        if (options_.stopAtEndOfStream && scansEnded_) {
          // The recorded scans are all used: a trigger now gets a not-inspected answer, and the
          // replay ends.
          if (trigger) {
            notInspected(std::move(job), PartError::NoInput, "no range scan left for the trigger");
          }
          break;
        }
        if (trigger) {
          notInspected(std::move(job), PartError::NoInput, "no range scan for the trigger");
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
        notInspected(std::move(job), PartError::NoFrame, "no frame within 2 s of the trigger");
        continue;
      case GrabStatus::Incomplete:
        metrics_.counter("facet_incomplete_frames_total", "Frames with missing pixel data")
            .increment();
        job->frame = std::move(grab.frame);
        notInspected(std::move(job), PartError::IncompleteFrame,
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
          notInspected(std::move(job), PartError::NoInput, "not inspected: " + grab.message);
          continue;
        }
        [[fallthrough]];
      case GrabStatus::Disconnected:
      case GrabStatus::NotStarted:
        metrics_.counter("facet_camera_errors_total", "Grabs that failed").increment();
        spdlog::warn("camera: {}: {}", toString(grab.status), grab.message);
        if (trigger) {
          notInspected(std::move(job), PartError::CameraUnavailable,
                       std::string("camera ") + toString(grab.status) + ": " + grab.message);
        }
        std::this_thread::sleep_for(100ms);
        continue;
    }
    if (endOfStream) {
      if (trigger) {
        // Every accepted trigger gets an answer, even when the replay has nothing left.
        notInspected(std::move(job), PartError::NoInput,
                     "replay finished: no image left for the trigger");
      }
      if (options_.stopAtEndOfStream) break;
      std::this_thread::sleep_for(50ms);
      continue;
    }
    stageLatency(metrics_, "grab").observe(msSince(t0));
    job->frame = std::move(grab.frame);
    takePart(*job);
    if (auto dropped = inspectQueue_.push(std::move(job)); dropped && *dropped) {
      metrics_.counter("facet_missed_parts_total", "Parts not inspected: inspection fell behind")
          .increment();
      publishNotInspected(std::move(*dropped), PartError::Missed, "missed: inspection fell behind");
    }
    metrics_.gauge("facet_queue_depth", "Items waiting per queue", "queue=\"inspect\"")
        .set(static_cast<double>(inspectQueue_.size()));
  }
  inspectQueue_.close();
}

bool Station::acquireScan(Job& job) {
  ScanResult next = scans_->next();
  if (next.status == GrabStatus::EndOfStream) scansEnded_ = true;
  if (next.status == GrabStatus::EndOfStream) return false;
  if (!next) {
    spdlog::error("scan replay: {}", next.message);
    return false;
  }
  job.frame = recordedScanFrame(next.scan);
  job.scan = std::move(next.scan.scan);
  return true;
}

void Station::inspectionLoop() {
  {
    const auto recipe = recipes_.active();
    const auto t0 = Clock::now();
    if (const auto outcome = options_.warmUp ? warmUp(*recipe) : std::nullopt)
      spdlog::info("recipe {}: warmed up on its picture of the part in {:.1f} ms ({})",
                   recipe->recipe().id, msSince(t0), verdictName(outcome->verdict));
    warmedUp_.count_down();
  }
  while (true) {
    inspectionBeat_ = nowTicks();
    auto job = inspectQueue_.pop(100ms);
    if (!job) {
      if (inspectQueue_.closed() && inspectQueue_.size() == 0) break;
      continue;
    }
    Job& j = **job;
    spdlog::debug("part={} inspecting {}", j.partId, j.frame.source);
    PartInput input;
    input.image = j.frame.image;
    input.scan = j.scan;
    if (!input.scan) input.scan = scanOfFrame(j.frame, j.partId);
    const InspectionOutcome outcome = inspectPart(input, *j.inspection);
    j.inspectedAt = Clock::now();
    PartResult& p = j.result;
    recordOutcome(p, outcome);
    j.overlay = outcome.overlay;
    stageLatency(metrics_, "inspect").observe(outcome.totalMs);
    publishQueue_.push(std::move(*job));
  }
  publishQueue_.close();
}

void Station::takePart(Job& job) {
  job.partId = nextPartId_++;
  ++partsTaken_;
  job.inspection = recipes_.choose(&job.frame, job.trigger ? &*job.trigger : nullptr);
}

void Station::notInspected(std::unique_ptr<Job> job, PartError code, const std::string& cause) {
  takePart(*job);
  publishNotInspected(std::move(job), code, cause);
}

void Station::publishNotInspected(std::unique_ptr<Job> job, PartError code,
                                  const std::string& cause) {
  job->error = code;
  job->result.verdict = Verdict::Error;
  job->result.error = cause;
  job->inspectedAt = Clock::now();
  publishQueue_.push(std::move(job));
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

}  // namespace facet::service
