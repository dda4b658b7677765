// libFuzzer target: the Modbus register map parser (plc/register_map_yaml.hpp), from YAML text.
// Expected outcome for bad input: RegisterMapError. A map that parses has passed validate(), so
// every result output in it must encode any measurement (including NaN, inf and values far out
// of range) without undefined behaviour, and decode back from its own words.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>

#include "plc/register_encoding.hpp"
#include "plc/register_map_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  facet::plc::RegisterMap map;
  try {
    map = facet::plc::parseRegisterMapText(text, "fuzz.yaml");
  } catch (const facet::plc::RegisterMapError&) {
    return 0;
  }
  if (!map.validate().empty()) std::abort();  // parse must have refused it
  for (const auto& output : map.results) {
    for (double value : {0.0, -1.5, 12345.678, 1e12, -1e300, std::nan(""),
                         std::numeric_limits<double>::infinity()}) {
      const auto encoded = facet::plc::encodeValue(output, value);
      (void)facet::plc::decodeValue(output, encoded.words.data());
    }
  }
  return 0;
}
