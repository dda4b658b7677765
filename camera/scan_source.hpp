#pragma once
// ScanSource: recorded 2D range scans replayed the way a folder of images is, for scan recipes.
// Files are read with the scan module's readers (algorithms/scan/scan_file.hpp, plain or
// gzip-compressed): *.csv is one scan per file ("x,y" or "angle_deg,range" rows); any other
// matching file is a CARMEN log whose FLASER messages are replayed one scan each.

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "algorithms/scan/scan.hpp"
#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

struct RangeScan {
  scan::Scan scan;           // metres, sensor frame (x forward, y left), beam order
  std::uint64_t id = 0;      // running number over the replay
  double timestamp_s = 0.0;  // CARMEN ipc_timestamp; 0 for CSV
  std::string source;        // "file" (CSV) or "file:line" (CARMEN)
  // CARMEN: "pose_x", "pose_y" (metres), "pose_theta" (radians) of the laser in the world.
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
  // The next scan in natural file order. A malformed or unreadable file is skipped with a
  // logged error naming file and line, and counted in health().skipped_files.
  virtual ScanResult next() = 0;
  virtual CameraHealth health() const = 0;
  virtual std::string name() const = 0;
};

// Lists the folder at once; throws CameraError when it is missing or holds no matching file.
std::unique_ptr<ScanSource> makeScanReplay(const ScanReplaySettings& settings);

}  // namespace facet
