#pragma once
// Range scans as parts: a recorded scan file taken as a part (scan recipes), and the scan a
// recorded image may carry with it (its sidecar's `scan` key).

#include <cstdint>
#include <optional>

#include "algorithms/scan/scan.hpp"
#include "camera/camera.hpp"
#include "camera/scan_source.hpp"

namespace facet::service {

// The part's frame for a recorded scan: id, source and metadata, with the scan file's sidecar
// (serial, expected verdict), as for images. No image.
Frame recordedScanFrame(const RangeScan& scan);

// The scan named by a recorded frame's sidecar, read beside the frame's file; none (logged
// with the part id) when the frame names none or it cannot be read.
std::optional<scan::Scan> scanOfFrame(const Frame& frame, std::uint64_t partId);

}  // namespace facet::service
