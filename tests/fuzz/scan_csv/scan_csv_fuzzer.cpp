// libFuzzer target: the CSV scan reader (algorithms/scan/scan_csv.hpp), from memory.
// Expected outcome for bad input: ScanFormatError naming the line. A scan read must hold only
// finite points (NaN/inf rows are dropped by contract).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "algorithms/scan/scan_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const facet::scan::Scan scan = facet::scan::readScanCsv(in, "fuzz.csv");
    for (const auto& p : scan.points)
      if (!std::isfinite(p.x()) || !std::isfinite(p.y())) std::abort();
  } catch (const facet::scan::ScanFormatError&) {
  }
  return 0;
}
