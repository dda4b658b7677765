#pragma once
// warmUp: runs a recipe once, before its first part, on a picture of the part.
//
// The first inspection of a process pays for work done once: the code's first run, the edge
// profile tables of the image's blur, a shape model's rotated top-level templates, the thread's
// kept search buffers. The first part of the bracket demo took 18-23 ms where the parts after it
// took 4-5. Run on the thread that inspects, before the first part, the warm-up moves most of
// that cost out of the part's cycle time. The picture is the first step's picture of the part
// (StepUnit::pictureOfPart: an align step's reference image, a shape step's template) with a
// border of its own edge pixels, so that the steps placed relative to it find room.

#include <optional>

#include "service/engine/inspect_part.hpp"

namespace facet::service {

// The inspection of the picture, or nothing when no step of the recipe has one (a range-scan
// recipe). Never throws; the outcome is for the log, not a part's.
std::optional<InspectionOutcome> warmUp(const PreparedRecipe& recipe);

}  // namespace facet::service
