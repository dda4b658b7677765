// ScanReplay: the ScanSource over a folder of CSV scans and CARMEN logs.

#include <deque>
#include <limits>
#include <mutex>

#include <spdlog/spdlog.h>

#include "algorithms/scan/scan_file.hpp"
#include "camera/image_file_list.hpp"
#include "camera/scan_source.hpp"

namespace facet {
namespace {

bool isCsv(const std::filesystem::path& file) {
  std::string name = file.filename().string();
  for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name.ends_with(".csv") || name.ends_with(".csv.gz");
}

class ScanReplay final : public ScanSource {
 public:
  explicit ScanReplay(ScanReplaySettings settings) : settings_(std::move(settings)) {
    if (settings_.folder.empty()) throw CameraError("scan replay: no folder given");
    if (settings_.max_range_m > 0.0) limits_.maxRange = settings_.max_range_m;
    files_ = listRecordedFiles(settings_.folder, settings_.glob,
                               {".csv", ".log", ".clf", ".carmen", ".gz"});
    if (files_.empty())
      throw CameraError("scan folder " + settings_.folder.string() + " has no scan file" +
                        (settings_.glob.empty() ? "" : " matching \"" + settings_.glob + "\""));
    health_.connected = true;
    health_.streaming = true;
  }

  ScanResult next() override {
    std::lock_guard lock(mutex_);
    // Refill from the next file until a scan is pending; one pass at most per call.
    for (std::size_t attempts = 0; pending_.empty() && attempts <= files_.size(); ++attempts) {
      if (next_file_ >= files_.size()) {
        if (!settings_.loop) return {GrabStatus::EndOfStream, {}, "scan replay finished"};
        next_file_ = 0;
      }
      load(files_[next_file_++]);
    }
    if (pending_.empty())
      return {GrabStatus::Error, {}, "no readable scan in " + settings_.folder.string()};
    RangeScan scan = std::move(pending_.front());
    pending_.pop_front();
    scan.id = next_id_++;
    ++health_.frames;
    return {GrabStatus::Ok, std::move(scan), {}};
  }

  CameraHealth health() const override {
    std::lock_guard lock(mutex_);
    return health_;
  }

  std::string name() const override { return "scan-replay:" + settings_.folder.string(); }

 private:
  void load(const std::filesystem::path& file) {
    const std::string path = file.string();
    try {
      if (isCsv(file)) {
        RangeScan scan;
        scan.scan = scan::readScanCsvFile(path, limits_);
        scan.source = path;
        pending_.push_back(std::move(scan));
        return;
      }
      const auto log = scan::readCarmenLogFile(path, limits_);
      if (log.empty()) throw std::runtime_error(path + ": no FLASER message");
      for (const auto& entry : log) {
        RangeScan scan;
        scan.scan = entry.scan;
        scan.timestamp_s = entry.timestamp;
        scan.source = path + ":" + std::to_string(entry.line);
        scan.metadata["pose_x"] = std::to_string(entry.pose.x);
        scan.metadata["pose_y"] = std::to_string(entry.pose.y);
        scan.metadata["pose_theta"] = std::to_string(entry.pose.theta);
        pending_.push_back(std::move(scan));
      }
    } catch (const std::exception& e) {  // ScanFormatError names file and line
      ++health_.skipped_files;
      health_.last_error = e.what();
      spdlog::error("scan replay: skipping {}", e.what());
    }
  }

  ScanReplaySettings settings_;
  scan::RangeLimits limits_;
  mutable std::mutex mutex_;
  std::vector<std::filesystem::path> files_;
  std::size_t next_file_ = 0;
  std::deque<RangeScan> pending_;
  std::uint64_t next_id_ = 0;
  CameraHealth health_;
};

}  // namespace

std::unique_ptr<ScanSource> makeScanReplay(const ScanReplaySettings& settings) {
  return std::make_unique<ScanReplay>(settings);
}

}  // namespace facet
