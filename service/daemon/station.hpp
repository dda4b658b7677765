#pragma once
// Station: one running facetd. Three stages run concurrently, joined by bounded queues:
//
//   acquisition  waits for a trigger (PLC) or free-runs, grabs a frame, has the recipe selector
//                choose the part's recipe (only here, so a switch happens between two parts)
//   inspection   runs the recipe on the frame (inspectPart, service/engine/); before the first
//                part, once on the active recipe's picture of the part (warmUp), and only then
//                does the PLC see the station ready
//   publishing   PLC registers (PlcPublisher), results store, image archive, metrics, last
//                result for HTTP (station_view.cpp)
//
// Every part that was triggered or grabbed gets a result: a frame that could not be grabbed,
// was incomplete, was a replay file that could not be read, or was dropped because inspection
// fell behind is published as Verdict::Error ("not inspected"), never as good. Results are
// never dropped between inspection and publishing (that queue blocks); the PLC link keeps its
// own bounded, counted queue.

#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <latch>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <opencv2/core.hpp>

#include "camera/camera.hpp"
#include "camera/scan_source.hpp"
#include "config/station_config.hpp"
#include "service/daemon/archive_writer.hpp"
#include "service/daemon/bounded_queue.hpp"
#include "service/daemon/image_archive.hpp"
#include "service/daemon/metrics.hpp"
#include "service/daemon/part_error.hpp"
#include "service/daemon/plc_publisher.hpp"
#include "service/daemon/recipe_selector.hpp"
#include "service/daemon/results_store.hpp"
#include "service/daemon/station_view.hpp"
#include "service/engine/inspect_part.hpp"

namespace facet::service {

struct StationOptions {
  OverflowPolicy overflow = OverflowPolicy::DropOldest;  // when inspection falls behind
  std::size_t inspectQueue = 4;                          // frames waiting for inspection
  // Results waiting for publishing. Each holds its frame (1.3 MB at 1280x1024), so this bounds
  // memory; a backlog beyond it waits upstream, where the overflow policy sees it.
  std::size_t publishQueue = 8;
  std::optional<int> recipe;       // recipe to start with (default: the lowest id)
  std::uint64_t maxParts = 0;      // stop after this many parts (0 = run until stopped)
  bool stopAtEndOfStream = false;  // replay without loop: stop once every file was inspected
  bool usePlc = true;              // false: no PLC link even if configured (none if not)
  // Run the active recipe once before the first part (service/engine/warm_up.hpp); off only to
  // measure what that saves.
  bool warmUp = true;
  std::function<void(const PartResult&)> onPart;  // called by the publishing stage, per part
};

class Station : public StationView {
 public:
  // Opens the results store, loads the recipes and prepares camera, PLC and archive. Throws
  // std::runtime_error with a clear message when the station cannot run at all (no usable
  // recipe, store not writable, camera backend unknown). Recipes may use the step kinds of
  // `kinds`, which must outlive the station.
  Station(config::StationConfig config, const config::StepKindRegistry& kinds,
          StationOptions options);
  ~Station() override;
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  // Starts the stages; returns once the camera is open (the PLC may still be connecting).
  void start();
  // Asks the stages to finish: no new parts are taken, queued parts are inspected and published.
  void requestStop();
  // Waits until the stages have finished (after requestStop(), maxParts or end of stream).
  void join();
  [[nodiscard]] bool finished() const { return finished_.load(); }
  // True once every stage has run out of work (maxParts reached, end of stream, or stop).
  [[nodiscard]] bool drained() const { return drained_.load(); }
  // Re-reads the recipes folder; a broken recipe is rejected and the one in use stays.
  config::ReloadReport reloadRecipes() { return recipes_.reload(); }
  [[nodiscard]] bool recipesChangedOnDisk() const { return recipes_.changedOnDisk(); }
  // Liveness of the acquisition and inspection loops (for the systemd watchdog).
  [[nodiscard]] bool loopsAlive(std::chrono::milliseconds within) const;
  // Whether the PLC link is connected (true when the station runs without a PLC).
  [[nodiscard]] bool plcConnected() const { return !plc_ || plc_->link().stats().connected; }

  // StationView (station_view.cpp)
  [[nodiscard]] nlohmann::json health() const override;
  [[nodiscard]] std::string metricsText() const override;
  [[nodiscard]] std::vector<PartResult> recentParts(std::size_t count) const override;
  [[nodiscard]] std::vector<PartResult> storedParts(std::uint64_t afterPartId,
                                                    std::size_t limit) const override;
  [[nodiscard]] std::vector<unsigned char> lastOverlayPng() const override;
  [[nodiscard]] nlohmann::json summary() const override;
  ActionOutcome selectRecipe(int recipeId) override;
  ActionOutcome resetCounters() override;

  [[nodiscard]] const config::StationConfig& config() const { return config_; }
  [[nodiscard]] MetricsRegistry& metrics() { return metrics_; }

 private:
  // One part on its way through the stages.
  struct Job {
    std::uint64_t partId = 0;
    Frame frame;
    std::optional<plc::TriggerEvent> trigger;
    std::optional<scan::Scan> scan;                    // scan recipes
    std::shared_ptr<const PreparedRecipe> inspection;  // the recipe chosen for the part
    std::chrono::steady_clock::time_point acquiredAt;
    std::chrono::steady_clock::time_point inspectedAt;
    PartResult result;
    PartError error = PartError::None;  // set for a part that was not inspected
    Overlay overlay;
  };
  // The three stages.
  void acquisitionLoop();
  void inspectionLoop();
  void publishingLoop();
  // Acquisition: numbers a part the acquisition took and chooses its recipe (once, with its
  // frame's sidecar when the frame is in the job, or the trigger).
  void takePart(Job& job);
  // Acquisition's one exit for a part that gets no inspection: taken, and published as
  // Verdict::Error with its cause, in its turn.
  void notInspected(std::unique_ptr<Job> job, PartError code, const std::string& cause);
  // The same for a part already taken (one the inspection queue dropped).
  void publishNotInspected(std::unique_ptr<Job> job, PartError code, const std::string& cause);
  // A scan recipe's part: the next recorded scan instead of a camera frame. False at the end.
  bool acquireScan(Job& job);
  // Publishing: PLC, results store, archive, metrics, what HTTP shows.
  void publishPart(Job& job);
  // What HTTP shows of a published part: counts, recent parts, the last picture (and the
  // archive, which keeps the pictures of failed parts). In station_view.cpp.
  void showPart(PartResult part, const cv::Mat& image, const Overlay& overlay);
  // Deletes parts the station file's retention no longer keeps, at most `limit` (0 = all): all
  // at start, then periodically between parts in slices of kRetentionSlice. Returns how many.
  std::int64_t applyRetention(std::int64_t limit);
  static constexpr std::chrono::seconds kRetentionPeriod{60};
  // About 10 ms of deleting here: a result waiting behind it is not held up longer than that.
  static constexpr std::int64_t kRetentionSlice = 500;
  // Parts the image archive may fall behind by before the oldest waiting one's pictures are
  // dropped (archive_writer.hpp): eight failed 1280x1024 parts, 0.6 s of writing.
  static constexpr std::size_t kArchiveQueue = 8;

  config::StationConfig config_;
  StationOptions options_;
  MetricsRegistry metrics_;
  std::unique_ptr<ResultsStore> store_;
  mutable std::mutex storeMutex_;  // SQLite connection shared by publishing and HTTP readers
  std::unique_ptr<ImageArchive> archive_;
  std::unique_ptr<ArchiveWriter> archiveWriter_;  // archive_'s writes, off the publishing thread
  RecipeSelector recipes_;
  std::unique_ptr<Camera> camera_;
  std::unique_ptr<ScanSource> scans_;  // recorded range scans for scan recipes (may be null)
  std::unique_ptr<PlcPublisher> plc_;

  BoundedQueue<std::unique_ptr<Job>> inspectQueue_;
  BoundedQueue<std::unique_ptr<Job>> publishQueue_;
  std::atomic<bool> stopRequested_{false};
  std::atomic<bool> finished_{false};
  std::atomic<bool> drained_{false};
  bool scansEnded_ = false;  // the scan replay has delivered every file (acquisition thread)
  bool archiveDegradedLogged_ = false;  // the archive state last logged (publishing thread)
  std::atomic<std::uint64_t> nextPartId_{1};
  std::uint64_t firstPartId_ = 1;  // the first id of this run (the store may hold older ones)
  std::atomic<std::uint64_t> partsTaken_{0};
  std::atomic<std::int64_t> acquisitionBeat_{0}, inspectionBeat_{0};
  std::thread acquisition_, inspection_, publishing_;
  // The inspection thread has run the active recipe once (warmUp), before the first part.
  std::latch warmedUp_{1};

  mutable std::mutex recentMutex_;
  std::deque<PartResult> recent_;
  // The last inspected image and what to draw on it; drawn when asked for (/api/last.png).
  struct LastPicture {
    cv::Mat image;
    Overlay overlay;
    std::string banner;
    bool pass = false;
    [[nodiscard]] cv::Mat draw() const { return drawOverlay(image, overlay, banner, pass); }
  };
  LastPicture lastPicture_;
  std::map<std::string, std::uint64_t> shiftCounts_;
  std::string lastStoreError_;
};

}  // namespace facet::service
