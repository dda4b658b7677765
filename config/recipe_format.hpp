#pragma once
// The recipe file format as tables (see field_spec.hpp): the top-level keys, a checked value,
// and one table per step kind. recipe_loader.cpp validates against these tables and
// json_schema.cpp turns them into recipes/recipe.schema.json.

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "config/field_spec.hpp"

namespace facet::config {

struct RecipeFormat {
  ObjectSpec recipe;                 // top level
  ObjectSpec check;                  // {nominal, tol_minus, tol_plus, unit, plc}
  ObjectSpec plcOutput;              // {register, type, scale}
  std::array<ObjectSpec, 6> checks;  // the `checks:` mapping of each step kind, same order
  std::vector<StepKindSpec> steps;   // align, fiducials, shape, circle, distance, scan_align

  RecipeFormat();
  RecipeFormat(const RecipeFormat&) = delete;  // the tables point into themselves
  RecipeFormat& operator=(const RecipeFormat&) = delete;

  [[nodiscard]] const StepKindSpec* stepKind(std::string_view kind) const;
  [[nodiscard]] std::vector<std::string> stepKindNames() const;
};

// The one instance, built on first use.
const RecipeFormat& recipeFormat();

}  // namespace facet::config
