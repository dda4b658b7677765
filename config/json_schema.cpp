#include "config/json_schema.hpp"

#include <map>

#include "config/recipe_format.hpp"
#include "config/station_format.hpp"

namespace facet::config {
namespace {

using nlohmann::json;

json numberSchema(const FieldSpec& f, const char* type) {
  json s{{"type", type}};
  if (f.minimum) s[f.exclusiveMinimum ? "exclusiveMinimum" : "minimum"] = *f.minimum;
  if (f.maximum) s["maximum"] = *f.maximum;
  return s;
}

json tuple(const FieldSpec& f, std::size_t n) {
  return {
      {"type", "array"}, {"items", numberSchema(f, "number")}, {"minItems", n}, {"maxItems", n}};
}

std::string definitionName(const ObjectSpec& spec) {
  std::string name = spec.name;
  for (char& c : name)
    if (c == ' ') c = '_';
  return name;
}

// Objects used by several fields (a checked value, a register location) are written once under
// "definitions" and referenced, which keeps the schema small enough to read.
class Generator {
 public:
  Generator(const ObjectSpec& root, const std::vector<StepKindSpec>& stepKinds)
      : stepKinds_(stepKinds) {
    count(root);
    for (const auto& k : stepKinds) count(k.object);
  }

  json document(const ObjectSpec& root) const {
    json s = object(root);
    json definitions = json::object();
    for (const auto& [spec, uses] : uses_)
      if (uses > 1) definitions[definitionName(*spec)] = object(*spec);
    if (!definitions.empty()) s["definitions"] = definitions;
    return s;
  }

 private:
  void count(const ObjectSpec& spec) {
    for (const auto& f : spec.fields) {
      if (!f.object) continue;
      if (++uses_[f.object] == 1) count(*f.object);
    }
  }

  json reference(const ObjectSpec& spec) const {
    const auto it = uses_.find(&spec);
    if (it != uses_.end() && it->second > 1)
      return {{"$ref", "#/definitions/" + definitionName(spec)}};
    return object(spec);
  }

  json object(const ObjectSpec& spec) const {
    json s{{"type", "object"}, {"additionalProperties", false}};
    if (!spec.description.empty()) s["description"] = spec.description;
    json properties = json::object();
    json required = json::array();
    for (const auto& f : spec.fields) {
      properties[f.name] = field(f);
      if (f.required) required.push_back(f.name);
    }
    s["properties"] = properties;
    if (!required.empty()) s["required"] = required;
    return s;
  }

  json field(const FieldSpec& f) const {
    json s = value(f);
    if (!f.description.empty()) s["description"] = f.description;
    if (!f.defaultValue.is_null()) s["default"] = f.defaultValue;
    return s;
  }

  json value(const FieldSpec& f) const {
    switch (f.type) {
      case FieldType::Integer:
        return numberSchema(f, "integer");
      case FieldType::Number:
        return numberSchema(f, "number");
      case FieldType::Boolean:
        return {{"type", "boolean"}};
      case FieldType::String:
      case FieldType::Path:
        return {{"type", "string"}, {"minLength", 1}};
      case FieldType::Identifier:
      case FieldType::StepRef:
        return {{"type", "string"}, {"pattern", "^[a-z][a-z0-9_]*$"}};
      case FieldType::Enum:
        if (f.choices.size() == 1) return {{"const", f.choices.front()}};
        return {{"enum", f.choices}};
      case FieldType::Point:
        return tuple(f, 2);
      case FieldType::PointList:
        return {{"type", "array"}, {"items", tuple(f, 2)}, {"minItems", f.minItems}};
      case FieldType::Range:
        return tuple(f, 2);
      case FieldType::Rect:
        return tuple(f, 4);
      case FieldType::Object:
        return reference(*f.object);
      case FieldType::ObjectList:
        return {{"type", "array"}, {"items", reference(*f.object)}, {"minItems", f.minItems}};
      case FieldType::StepList: {
        json kinds = json::array();
        for (const auto& k : stepKinds_) kinds.push_back(object(k.object));
        return {{"type", "array"}, {"items", {{"oneOf", kinds}}}, {"minItems", f.minItems}};
      }
    }
    return json::object();
  }

  const std::vector<StepKindSpec>& stepKinds_;
  std::map<const ObjectSpec*, int> uses_;
};

}  // namespace

nlohmann::json jsonSchema(const ObjectSpec& root, const std::vector<StepKindSpec>& stepKinds,
                          const std::string& id) {
  json s = Generator(root, stepKinds).document(root);
  json head{{"$schema", "http://json-schema.org/draft-07/schema#"},
            {"$id", id},
            {"title", "facet " + root.name}};
  head.update(s);
  return head;
}

nlohmann::json recipeJsonSchema(const StepKindRegistry& kinds) {
  const RecipeFormat f(kinds);
  return jsonSchema(f.recipe, f.steps, "https://facet.invalid/schema/recipe.schema.json");
}

nlohmann::json stationJsonSchema() {
  return jsonSchema(stationFormat().station, {},
                    "https://facet.invalid/schema/station.schema.json");
}

}  // namespace facet::config
