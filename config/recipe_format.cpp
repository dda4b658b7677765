#include "config/recipe_format.hpp"

namespace facet::config {
namespace {

using F = FieldType;

ObjectSpec plcOutputFormat() {
  return {"plc output",
          "Holding register the measured value is written to (see the station's "
          "register_map for the address base).",
          {{.name = "register",
            .type = F::Integer,
            .description = "First holding register.",
            .required = true,
            .minimum = 0.0,
            .maximum = 65535.0},
           {.name = "type",
            .type = F::Enum,
            .description = "Encoding: int16 / scaled_int16 one register, int32 / "
                           "scaled_int32 / float32 two.",
            .choices = {"int16", "int32", "scaled_int16", "scaled_int32", "float32"},
            .defaultValue = "float32"},
           {.name = "factor",
            .type = F::Number,
            .description = "Scaled types hold round(value * factor), e.g. 1000 for "
                           "micrometres; required for them, refused for the others.",
            .minimum = 0.0,
            .exclusiveMinimum = true},
           {.name = "word_order",
            .type = F::Enum,
            .description = "Order of the bytes of a 32-bit value; default: the station's "
                           "plc.word_order.",
            .choices = {"ABCD", "CDAB", "BADC", "DCBA"}}}};
}

}  // namespace

const ObjectSpec& checkFormat() {
  static const ObjectSpec plcOutput = plcOutputFormat();
  static const ObjectSpec check{
      "check",
      "A checked value: passes when nominal - tol_minus <= measured <= nominal + tol_plus.",
      {{.name = "nominal",
        .type = F::Number,
        .description = "Nominal value in `unit`.",
        .required = true},
       {.name = "tol_minus",
        .type = F::Number,
        .description = "Allowed deviation below nominal, >= 0.",
        .required = true,
        .minimum = 0.0},
       {.name = "tol_plus",
        .type = F::Number,
        .description = "Allowed deviation above nominal, >= 0.",
        .required = true,
        .minimum = 0.0},
       {.name = "unit",
        .type = F::Enum,
        .description = "mm or px for lengths (default mm; for areas mm^2 or px^2), deg for "
                       "angles; none for counts and scores.",
        .choices = {"mm", "deg", "px"}},
       {.name = "plc",
        .type = F::Object,
        .description = "Where the measured value goes on the PLC.",
        .object = &plcOutput}}};
  return check;
}

FieldSpec checkField(std::string name, Quantity quantity, std::string description,
                     std::optional<double> minimum) {
  return {.name = std::move(name),
          .type = F::Object,
          .description = std::move(description),
          .minimum = minimum,
          .object = &checkFormat(),
          .quantity = quantity};
}

StepKindSpec stepFormat(std::string kind, std::string description, std::vector<FieldSpec> own,
                        const ObjectSpec& checks) {
  ObjectSpec spec{kind + " step", std::move(description), {}};
  spec.fields.push_back({.name = "id",
                         .type = F::Identifier,
                         .description = "Unique name of the step in the recipe "
                                        "([a-z][a-z0-9_]*); later steps refer to it.",
                         .required = true});
  spec.fields.push_back({.name = "kind",
                         .type = F::Enum,
                         .description = "Step kind.",
                         .required = true,
                         .choices = {kind}});
  spec.fields.push_back(
      {.name = "name", .type = F::String, .description = "Display name; default: the id."});
  for (auto& f : own) spec.fields.push_back(std::move(f));
  spec.fields.push_back({.name = "checks",
                         .type = F::Object,
                         .description = "Checked values of this step; the part fails when one "
                                        "is out of tolerance.",
                         .object = &checks});
  return {std::move(kind), std::move(spec)};
}

RecipeFormat::RecipeFormat(const StepKindRegistry& kinds) : steps(kinds.formats()) {
  recipe = {"recipe",
            "A facet inspection recipe: what the line checks on one part type.",
            {{.name = "schema_version",
              .type = F::Integer,
              .description = "Version of this format; 1.",
              .required = true,
              .minimum = 1.0,
              .maximum = 1.0},
             {.name = "id",
              .type = F::Integer,
              .description = "Number the PLC selects the recipe by, unique in the folder.",
              .required = true,
              .minimum = 1.0,
              .maximum = 65535.0},
             {.name = "name", .type = F::String, .description = "Display name.", .required = true},
             {.name = "version", .type = F::String, .description = "Free-text version."},
             {.name = "description", .type = F::String, .description = "Free text."},
             {.name = "steps",
              .type = F::StepList,
              .description = "Steps, run in order; a step may use results of earlier steps.",
              .required = true,
              .minItems = 1}}};
}

}  // namespace facet::config
