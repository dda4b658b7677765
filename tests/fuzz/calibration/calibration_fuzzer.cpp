// libFuzzer target: the calibration file reader (config/calibration_file.hpp), both facet's YAML
// format and OpenCV FileStorage files. Expected outcome for bad input: diagnostics; data is
// returned exactly when there is no error, and then it is usable (a mapping can be built).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "config/calibration_file.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const facet::fuzz::FuzzInputFolder folder;
  const auto file = folder.write("calibration.yaml", data, size);
  facet::config::Diagnostics diagnostics;
  const auto result = facet::config::readCalibrationFile(file, diagnostics);
  if (result.has_value() == diagnostics.hasErrors()) std::abort();
  if (result && result->camera && result->plane) {
    const facet::WorldMapping mapping(*result->camera, *result->plane);
    (void)mapping.toPlane({10.0, 10.0});
  }
  return 0;
}
