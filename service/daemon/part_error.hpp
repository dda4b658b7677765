#pragma once
// PartError: why a part has no verdict, as facetd writes it to the PLC's error_code register
// with the error bit. A PLC program or HMI can tell a camera problem from an overrun or a recipe
// step that could not measure without reading facetd's log. The values are part of the PLC
// interface (deploy/README.md): never renumber them.

#include <cstdint>

namespace facet::service {

enum class PartError : std::uint16_t {
  None = 0,               // the part was inspected (pass or fail)
  InspectionFailed = 1,   // a recipe step could not measure (the part was looked at)
  NoFrame = 2,            // no frame within 2 s of the trigger
  IncompleteFrame = 3,    // the frame arrived with image data missing (lost packets)
  CameraUnavailable = 4,  // camera disconnected or not started, or the grab failed
  Missed = 5,             // inspection fell behind: the part was dropped from the queue
  NoInput = 6,            // replay: no image or scan left, or a recorded file was refused
};

}  // namespace facet::service
