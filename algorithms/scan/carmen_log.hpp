#pragma once
// Reader for CARMEN log files: the FLASER (front laser) messages, other message types skipped.
//
//   FLASER n r1 ... rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
//
// Beams spread evenly over 180 degrees starting at -90 degrees: angle step 180 / (n - n mod 2)
// degrees. x y theta is the (here SLAM-corrected) laser pose in the world frame. Pure parsing
// of a stream; opening (and un-gzipping) files is scan_file.hpp's job.

#include <istream>
#include <string>
#include <vector>

#include "algorithms/scan/scan.hpp"
#include "algorithms/scan/scan_format_error.hpp"
#include "algorithms/scan/scan_pose.hpp"

namespace facet::scan {

struct CarmenLaserScan {
  Scan scan;               // returns only (NaN/inf/max-range beams dropped), sensor frame
  ScanPose pose;           // laser pose in the world frame (x, y metres; theta radians)
  ScanPose odometry;       // odometry pose
  double timestamp = 0.0;  // ipc_timestamp, seconds
  int line = 0;            // line in the log, 1-based
};

// Reads all FLASER messages. Throws ScanFormatError naming `source` and the line of the first
// malformed FLASER message.
[[nodiscard]] std::vector<CarmenLaserScan> readCarmenLog(std::istream& in,
                                                         const std::string& source,
                                                         const RangeLimits& limits = {});

}  // namespace facet::scan
