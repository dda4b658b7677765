#pragma once
// The description of a YAML file format as plain tables: one ObjectSpec per mapping, one
// FieldSpec per key. The same tables drive the validator (yaml_validation.hpp), which reports
// unknown keys, wrong types and out-of-range values with their line and column, and the JSON
// schema generator (json_schema.hpp), which editors use for completion. A key therefore cannot
// be accepted by one and unknown to the other.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace facet::config {

struct ObjectSpec;

enum class FieldType {
  Integer,     // a whole number
  Number,      // a real number
  Boolean,     // true / false
  String,      // any scalar text
  Identifier,  // [a-z][a-z0-9_]*: step ids, names code refers to
  StepRef,     // the Identifier of an earlier step of the same recipe
  Enum,        // one of `choices`
  Path,        // a file path, relative to the file that names it
  Point,       // [x, y]
  PointList,   // [[x, y], ...]
  Range,       // [low, high] with low <= high
  Rect,        // [x, y, width, height] with width, height > 0
  Object,      // a mapping described by `object`
  ObjectList,  // a sequence of mappings described by `object`
  StepList,    // the recipe's ordered steps; each item's `kind` chooses its ObjectSpec
};

// What a checked value measures. It decides the allowed units and whether the nominal value is
// inherently non-negative (a diameter is, a position offset is not). An area's units are the
// squares of a length's (mm and px in the file mean mm^2 and px^2).
enum class Quantity { Length, Angle, Count, Score, Area };

struct FieldSpec {
  std::string name;
  FieldType type = FieldType::String;
  std::string description;
  bool required = false;
  std::optional<double> minimum;  // Integer, Number, Point/Range/Rect elements
  std::optional<double> maximum;
  bool exclusiveMinimum = false;       // minimum itself is not allowed (e.g. a diameter > 0)
  std::vector<std::string> choices;    // Enum
  const ObjectSpec* object = nullptr;  // Object, ObjectList
  std::size_t minItems = 0;            // ObjectList, PointList, StepList
  nlohmann::json defaultValue;         // documented default, null when none
  std::optional<Quantity> quantity;    // set for the entries of a step's `checks`
  // The value is checked by its owner's own parser (the PLC register map): the validator only
  // checks that it is a mapping; the schema still describes it.
  bool validatedByOwner = false;
};

struct ObjectSpec {
  std::string name;  // used in messages: "unknown key 'x' in circle step"
  std::string description;
  std::vector<FieldSpec> fields;

  [[nodiscard]] const FieldSpec* find(std::string_view key) const {
    for (const auto& f : fields)
      if (f.name == key) return &f;
    return nullptr;
  }
};

// A step kind of the recipe format: its name as written after `kind:` and its keys.
struct StepKindSpec {
  std::string kind;
  ObjectSpec object;
};

}  // namespace facet::config
