#pragma once
// The interface between makeCamera (aravis_backend.cpp) and the GigE Vision camera module that
// implements the aravis backend (libfacet_aravis_camera.so, aravis_camera_module.cpp). The module
// links Aravis and through it GLib, GObject and GIO: 16 libraries that every start of facet and
// facetd loaded when they were linked; only a program that makes an aravis camera loads it now.
//
// Both sides are built together by this project with one compiler, so the table passes C++ types
// (the settings, the Camera, CameraError thrown by the module); `abi` guards against a module
// left over from another build.

#include <memory>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

// Raise whenever a member or a signature below changes, or Camera, CameraError or AravisSettings.
inline constexpr int kAravisCameraAbi = 1;

struct AravisCameraTable {
  int abi = kAravisCameraAbi;
  // AravisCamera's constructor: a closed camera; throws CameraError for unusable settings.
  std::unique_ptr<Camera> (*make)(const AravisSettings& settings);
};

}  // namespace facet

// The module's one exported symbol.
extern "C" const facet::AravisCameraTable* facet_aravis_camera_table();
inline constexpr const char* kAravisCameraEntry = "facet_aravis_camera_table";
