#include "service/engine/warm_up.hpp"

#include <algorithm>
#include <exception>

#include <opencv2/core.hpp>

namespace facet::service {

std::optional<InspectionOutcome> warmUp(const PreparedRecipe& recipe) {
  const auto& steps = recipe.recipe().steps;
  for (std::size_t i = 0; i < steps.size() && i < recipe.units.size(); ++i) {
    const cv::Mat picture = recipe.units[i]->pictureOfPart(steps[i]);
    if (picture.empty()) continue;
    // A quarter of the picture's size on each side: steps placed relative to the part near or
    // past the picture's edges find image to measure on.
    const int border = std::max(picture.cols, picture.rows) / 4;
    cv::Mat frame;
    try {
      cv::copyMakeBorder(picture, frame, border, border, border, border, cv::BORDER_REPLICATE);
    } catch (const std::exception&) {
      return std::nullopt;  // no memory for it: the first part pays, as without a warm-up
    }
    return inspectPart({.image = frame, .scan = std::nullopt}, recipe);
  }
  return std::nullopt;
}

}  // namespace facet::service
