// libFuzzer target: the Modbus register map parser (plc/register_map_yaml.hpp), from YAML text.
// Expected outcome for bad input: RegisterMapError. Anything else escaping is a finding.

#include <cstddef>
#include <cstdint>
#include <string>

#include "plc/register_map_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const facet::plc::RegisterMap map = facet::plc::parseRegisterMapText(text, "fuzz.yaml");
    // A map that parsed must describe itself without trouble.
    (void)map.validate();
  } catch (const facet::plc::RegisterMapError&) {
  }
  return 0;
}
