#pragma once
// JSON schemas (draft-07, what editors' YAML plugins read) generated from the format tables, so
// that editor completion and the validator always agree. The shipped copies in recipes/ are
// compared with these by a test; regenerate them with `facet recipe schema`.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/field_spec.hpp"
#include "config/step_kind.hpp"

namespace facet::config {

nlohmann::json jsonSchema(const ObjectSpec& root, const std::vector<StepKindSpec>& stepKinds,
                          const std::string& id);

// recipes/recipe.schema.json for the step kinds of `kinds`.
nlohmann::json recipeJsonSchema(const StepKindRegistry& kinds);
nlohmann::json stationJsonSchema();  // recipes/station.schema.json

}  // namespace facet::config
