#pragma once
// ScanSource: recorded 2D range scans replayed the way a folder of images is, for scan recipes.
// Formats: CSV (rows "x,y" in metres, one scan per file; or "scan,x,y" with several scans per
// file, grouped by the first column; a non-numeric first row is a header) and CARMEN logs
// (FLASER / RLASER / RAWLASER lines; ranges turned into points in the sensor frame).

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

struct RangeScan {
  std::vector<cv::Point2d> points;  // metres, sensor frame: x forward, y left
  std::uint64_t id = 0;             // running number over the replay
  double timestamp_s = 0.0;         // from the log when it has one, else 0
  std::string source;               // "file" or "file:line"
  std::map<std::string, std::string> metadata;
};

struct ScanResult {
  GrabStatus status = GrabStatus::Error;  // Ok, EndOfStream or Error
  RangeScan scan;
  std::string message;
  explicit operator bool() const { return status == GrabStatus::Ok; }
};

class ScanSource {
 public:
  virtual ~ScanSource() = default;
  // The next scan in natural file order. A malformed file or line is skipped with a logged
  // error naming file and line, and counted in health().skipped_files.
  virtual ScanResult next() = 0;
  virtual CameraHealth health() const = 0;
  virtual std::string name() const = 0;
};

// Throws CameraError when the folder is missing or holds no matching file.
std::unique_ptr<ScanSource> makeScanReplay(const ScanReplaySettings& settings);

}  // namespace facet
