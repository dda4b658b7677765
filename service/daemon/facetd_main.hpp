#pragma once
// The facetd program as a function of the step kinds its recipes may use.

#include "config/step_kind.hpp"

namespace facet::service {

int runFacetd(int argc, char** argv, const config::StepKindRegistry& kinds);

}  // namespace facet::service
