#pragma once
// The aravis camera backend for makeCamera, through a module loaded when the first aravis camera
// is made (libfacet_aravis_camera.so: AravisCamera with Aravis, GLib, GObject and GIO). Linked,
// those made every start of `facet` and `facetd` load 16 more libraries, also for the commands
// and stations that never open a GigE Vision camera.
//
// The module is looked for in FACET_ARAVIS_CAMERA (a file, then the only place tried), else beside
// the executable's install layout (<bin>/../lib/facet/), else in the build tree that built this
// program; it is loaded once per process (thread-safe) and stays loaded.

#include <memory>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

// An AravisCamera, returned closed. Throws CameraError for unusable settings, and when the module
// or the libraries it needs cannot be loaded: then the message names every path tried with the
// loader's reason (e.g. libaravis-0.8.so.0 missing: install libaravis-0.8-0).
std::unique_ptr<Camera> makeAravisCamera(const AravisSettings& settings);

}  // namespace facet
