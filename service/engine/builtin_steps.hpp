#pragma once
// The step kinds facet ships. facetd and `facet` read recipes with this registry; a program
// that adds its own kinds starts from it and adds them (see docs/architecture.md).

#include "config/step_kind.hpp"

namespace facet::service {

config::StepKindRegistry builtinSteps();

}  // namespace facet::service
