#include "algorithms/measure/measure_failure.hpp"

namespace facet {

std::string_view toString(MeasureFailure failure) {
  switch (failure) {
    case MeasureFailure::None:
      return "none";
    case MeasureFailure::ZeroSize:
      return "zero_size";
    case MeasureFailure::OutsideImage:
      return "outside_image";
    case MeasureFailure::NoContrast:
      return "no_contrast";
    case MeasureFailure::NoEdge:
      return "no_edge";
    case MeasureFailure::NoPair:
      return "no_pair";
    case MeasureFailure::TooFewPoints:
      return "too_few_points";
    case MeasureFailure::NoBlob:
      return "no_blob";
  }
  return "unknown";
}

}  // namespace facet
