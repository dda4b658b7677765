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

LoadedBackend load() {
  const ModuleFile module{"FACET_ARAVIS_CAMERA", FACET_ARAVIS_CAMERA_FILE,
                          FACET_ARAVIS_CAMERA_FROM_BIN, FACET_ARAVIS_CAMERA_BUILD_PATH};
  std::string tried;
  if (const auto* table =
          openModuleTable<AravisCameraTable>(module, kAravisCameraEntry, kAravisCameraAbi, tried))
    return {table, {}};
  return {nullptr,
          "the GigE Vision camera module cannot be loaded (install libaravis-0.8-0, or "
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
