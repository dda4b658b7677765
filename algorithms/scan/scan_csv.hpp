#pragma once
// Reader for scans in CSV, one beam per line, in beam order:
//   - `x,y` in metres (sensor frame), with or without a header line `x,y`;
//   - `angle_deg,range` (degrees, metres) after a header naming those columns (in any order;
//     `angle` is accepted for `angle_deg`).
// Blank lines and lines starting with '#' are skipped. NaN, inf and out-of-limit ranges are
// dropped (x,y rows with NaN/inf coordinates too). Pure parsing of a stream.

#include <istream>
#include <string>

#include "algorithms/scan/scan.hpp"
#include "algorithms/scan/scan_format_error.hpp"

namespace facet::scan {

// Throws ScanFormatError naming `source` and the line of the first malformed row.
[[nodiscard]] Scan readScanCsv(std::istream& in, const std::string& source,
                               const RangeLimits& limits = {});

}  // namespace facet::scan
