#pragma once
// Opening scan files (library facet_scan_io, which owns the file I/O and zlib): plain or
// gzip-compressed, chosen by content, not by name.

#include <string>
#include <vector>

#include "algorithms/scan/carmen_log.hpp"
#include "algorithms/scan/scan_csv.hpp"

namespace facet::scan {

// Reads a whole file, gunzipping it when it is gzip-compressed. Throws std::runtime_error
// naming the file when it cannot be opened or decompressed.
[[nodiscard]] std::string readTextFile(const std::string& path);

[[nodiscard]] std::vector<CarmenLaserScan> readCarmenLogFile(const std::string& path,
                                                             const RangeLimits& limits = {});
[[nodiscard]] Scan readScanCsvFile(const std::string& path, const RangeLimits& limits = {});

}  // namespace facet::scan
