#pragma once
// The recipe's words for the grey-value polarity of a round feature (circle, fiducial marks).

#include <string>
#include <utility>
#include <vector>

#include "algorithms/circle/circle_measure.hpp"

namespace facet::service {

inline std::vector<std::pair<std::string, CirclePolarity>> circlePolarityNames() {
  return {{"dark_inside", CirclePolarity::DarkToLight},
          {"light_inside", CirclePolarity::LightToDark},
          {"any", CirclePolarity::Any}};
}

}  // namespace facet::service
