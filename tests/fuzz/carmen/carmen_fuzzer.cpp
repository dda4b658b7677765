// libFuzzer target: the CARMEN log reader (algorithms/scan/carmen_log.hpp), from memory.
// Expected outcome for bad input: ScanFormatError naming the line. Every scan read must hold
// only finite points (NaN/inf beams are dropped by contract).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "algorithms/scan/carmen_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    for (const auto& laser : facet::scan::readCarmenLog(in, "fuzz.log")) {
      for (const auto& p : laser.scan.points)
        if (!std::isfinite(p.x()) || !std::isfinite(p.y())) std::abort();
    }
  } catch (const facet::scan::ScanFormatError&) {
  }
  return 0;
}
