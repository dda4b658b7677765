#pragma once
// Why a measuring tool gave no result. A tool never reports a made-up position: when it cannot
// measure, its Status<MeasureFailure> (algorithms/status) says why with one of these causes and
// a sentence for the engineer.

#include <string_view>

namespace facet {

enum class MeasureFailure {
  None,
  ZeroSize,      // the rectangle, arc or region has no extent
  OutsideImage,  // it lies wholly outside the image
  NoContrast,    // the grey values inside vary less than the minimum amplitude
  NoEdge,        // contrast, but no edge passes polarity and minimum amplitude
  NoPair,        // edges, but no pair of opposite polarity
  TooFewPoints,  // line: too few edge points for a fit
  NoBlob,        // blob: nothing left after thresholding and the filters
};

// snake_case name for JSON and logs ("zero_size", "outside_image", ...).
[[nodiscard]] std::string_view toString(MeasureFailure failure);

}  // namespace facet
