#pragma once
// The recipe file format as tables (see field_spec.hpp): the top-level keys, a checked value and
// its PLC output, and the step kinds of a registry (each kind brings its own table, see
// step_kind.hpp). recipe_loader.cpp validates against these tables and json_schema.cpp turns
// them into recipes/recipe.schema.json.

#include <string>
#include <vector>

#include "config/field_spec.hpp"
#include "config/step_kind.hpp"

namespace facet::config {

struct RecipeFormat {
  ObjectSpec recipe;                // top level
  std::vector<StepKindSpec> steps;  // the registry's kinds, in its order

  explicit RecipeFormat(const StepKindRegistry& kinds);
};

// A checked value ({nominal, tol_minus, tol_plus, unit, plc}), shared by every kind's checks.
const ObjectSpec& checkFormat();

// One entry of a kind's `checks:` mapping.
FieldSpec checkField(std::string name, Quantity quantity, std::string description,
                     std::optional<double> minimum = std::nullopt);

// A step kind's table: the keys every step has (id, kind, name), the kind's own keys, and its
// `checks` mapping described by `checks` (which must outlive the result: the kind owns both).
StepKindSpec stepFormat(std::string kind, std::string description, std::vector<FieldSpec> own,
                        const ObjectSpec& checks);

}  // namespace facet::config
