// libFuzzer target: the station config parser and validator (config/station_config.hpp). Each
// input is a station file in a folder that also holds recipes/, demo/ and a calibration file,
// so that inputs naming them reach the checks behind. Expected outcome for bad input:
// diagnostics; a station is returned exactly when there is no error.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>

#include "config/station_config.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

namespace {

const facet::fuzz::FuzzInputFolder& stationFolder() {
  static const facet::fuzz::FuzzInputFolder folder;
  static const bool filled = [] {
    const auto& root = folder.path();
    std::filesystem::create_directories(root / "recipes");
    std::filesystem::create_directories(root / "demo");
    std::ofstream calibration(root / "calibration.yaml");
    calibration << "%YAML:1.0\n---\n"
                   "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                   "   data: [ 2400., 0., 319.5, 0., 2400., 239.5, 0., 0., 1. ]\n"
                   "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n"
                   "   dt: d\n   data: [ -0.012, 0.004, 0., 0., 0. ]\n"
                   "mm_per_pixel: 0.05\n";
    return true;
  }();
  (void)filled;
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& folder = stationFolder();
  const auto file = folder.write("station.yaml", data, size);
  const auto result = facet::config::loadStationConfig(file);
  if (result.station.has_value() == result.diagnostics.hasErrors()) std::abort();
  return 0;
}
