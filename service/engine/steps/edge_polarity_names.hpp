#pragma once
// The recipe's words for an edge's polarity along a measuring axis and for which edges count
// (caliper, line).

#include <string>
#include <utility>
#include <vector>

#include "algorithms/measure/caliper.hpp"

namespace facet::service {

inline std::vector<std::pair<std::string, EdgePolarity>> edgePolarityNames() {
  return {{"any", EdgePolarity::Any},
          {"rising", EdgePolarity::Rising},
          {"falling", EdgePolarity::Falling}};
}

inline std::vector<std::pair<std::string, EdgeSelect>> edgeSelectNames() {
  return {{"all", EdgeSelect::All},
          {"first", EdgeSelect::First},
          {"last", EdgeSelect::Last},
          {"strongest", EdgeSelect::Strongest}};
}

}  // namespace facet::service
