#include "camera/aravis_backend.hpp"

#include <string>

#include "camera/aravis_camera_table.hpp"
#include "camera/module_file.hpp"

// Baked in by camera/CMakeLists.txt.
#ifndef FACET_ARAVIS_CAMERA_FILE
#error "FACET_ARAVIS_CAMERA_FILE (the module's file name) is not defined"
#endif

namespace facet {
namespace {

struct LoadedBackend {
  const AravisCameraTable* table = nullptr;
  std::string problem;  // empty when `table` is set
};

const AravisCameraTable* tableOf(void* entry) {
  return reinterpret_cast<decltype(&facet_aravis_camera_table)>(entry)();
}

LoadedBackend load() {
  const ModuleFile module{"FACET_ARAVIS_CAMERA", FACET_ARAVIS_CAMERA_FILE,
                          FACET_ARAVIS_CAMERA_FROM_BIN, FACET_ARAVIS_CAMERA_BUILD_PATH};
  const auto accept = [](void* entry) -> std::string {
    const AravisCameraTable* table = tableOf(entry);
    if (!table) return std::string("no table from ") + kAravisCameraEntry;
    if (table->abi == kAravisCameraAbi) return {};
    return "built for interface " + std::to_string(table->abi) + ", this program needs " +
           std::to_string(kAravisCameraAbi);
  };
  std::string tried;
  if (void* entry = openModule(module, kAravisCameraEntry, accept, tried))
    return {tableOf(entry), {}};
  return {nullptr, "the GigE Vision camera module cannot be loaded (install libaravis-0.8-0, or "
                   "set FACET_ARAVIS_CAMERA to the module " +
                       std::string(FACET_ARAVIS_CAMERA_FILE) + "); tried " + tried};
}

}  // namespace

std::unique_ptr<Camera> makeAravisCamera(const AravisSettings& settings) {
  static const LoadedBackend backend = load();  // once, thread-safe
  if (!backend.table) throw CameraError("aravis camera: " + backend.problem);
  return backend.table->make(settings);
}

}  // namespace facet
