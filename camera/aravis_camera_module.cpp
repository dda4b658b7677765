// The GigE Vision camera module (libfacet_aravis_camera.so): the table that aravis_backend.cpp
// loads. The only exported symbol is its entry point; AravisCamera stays inside the module.
#include "camera/aravis_camera.hpp"
#include "camera/aravis_camera_table.hpp"

namespace facet {
namespace {

std::unique_ptr<Camera> make(const AravisSettings& settings) {
  return std::make_unique<AravisCamera>(settings);
}

constexpr AravisCameraTable kTable{.abi = kAravisCameraAbi, .make = make};

}  // namespace
}  // namespace facet

extern "C" __attribute__((visibility("default"))) const facet::AravisCameraTable*
facet_aravis_camera_table() {
  return &facet::kTable;
}
