#include "config/yaml_validation.hpp"

#include <algorithm>
#include <cstdio>
#include <map>

#include "config/closest_name.hpp"
#include "config/yaml_document.hpp"

namespace facet::config {
namespace {

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// [a-z][a-z0-9_]*
bool isIdentifier(const std::string& s) {
  if (s.empty() || s[0] < 'a' || s[0] > 'z') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// "must be between 0 and 1 (got 1.5)", or nothing when `value` is in the field's range.
std::optional<std::string> rangeProblem(double value, const FieldSpec& f) {
  const bool tooLow = f.minimum && (f.exclusiveMinimum ? value <= *f.minimum : value < *f.minimum);
  const bool tooHigh = f.maximum && value > *f.maximum;
  if (!tooLow && !tooHigh) return std::nullopt;
  std::string rule;
  if (f.minimum && f.maximum && *f.minimum == *f.maximum)
    rule = "must be " + formatNumber(*f.minimum);
  else if (f.minimum && f.maximum && !f.exclusiveMinimum)
    rule = "must be between " + formatNumber(*f.minimum) + " and " + formatNumber(*f.maximum);
  else if (tooLow)
    rule = (f.exclusiveMinimum ? "must be greater than " : "must be at least ") +
           formatNumber(*f.minimum);
  else
    rule = "must be at most " + formatNumber(*f.maximum);
  return rule + " (got " + formatNumber(value) + ")";
}

class Validator {
 public:
  Validator(const std::filesystem::path& file, Diagnostics& out,
            const std::vector<StepKindSpec>& stepKinds)
      : file_(file), out_(out), stepKinds_(stepKinds) {}

  void object(const YAML::Node& node, const ObjectSpec& spec, const std::string& what) {
    if (!node.IsMap()) {
      error(node, what + " must be a mapping of keys to values, not " + describe(node));
      return;
    }
    std::map<std::string, YAML::Node> seen;
    for (const auto& entry : node) {
      const YAML::Node& key = entry.first;
      const std::string name = key.IsScalar() ? key.Scalar() : describe(key);
      if (const auto it = seen.find(name); it != seen.end()) {
        const SourceLocation first = locate(file_, it->second);
        error(key, "duplicate key " + inQuotes(name) + " (first given at line " +
                       std::to_string(first.line) + ")");
        continue;
      }
      seen.emplace(name, key);
      const FieldSpec* field = spec.find(name);
      if (!field) {
        unknownKey(key, name, spec);
        continue;
      }
      value(entry.second, *field, key);
    }
    for (const auto& f : spec.fields)
      if (f.required && !seen.contains(f.name))
        error(node, spec.name + " is missing required key " + inQuotes(f.name));
  }

 private:
  void error(const YAML::Node& node, std::string message) {
    out_.error(locate(file_, node), std::move(message));
  }

  void unknownKey(const YAML::Node& key, const std::string& name, const ObjectSpec& spec) {
    std::vector<std::string> names;
    for (const auto& f : spec.fields) names.push_back(f.name);
    std::string message = "unknown key " + inQuotes(name) + " in " + spec.name;
    if (const auto near = closestName(name, names))
      message += " (did you mean " + inQuotes(*near) + "?)";
    else
      message += " (valid keys: " + joined(names) + ")";
    error(key, message);
  }

  // Where to point for a problem with a value: at the value, or at its key when yaml-cpp has no
  // position for the value (an empty value).
  const YAML::Node& at(const YAML::Node& v, const YAML::Node& key) {
    return v.Mark().is_null() || v.IsNull() ? key : v;
  }

  std::optional<double> number(const YAML::Node& v, const YAML::Node& key, const FieldSpec& f,
                               const std::string& what) {
    const auto x = readNumber(v);
    if (!x) {
      error(at(v, key), what + " must be a number, not " + describe(v));
      return std::nullopt;
    }
    if (const auto problem = rangeProblem(*x, f)) error(at(v, key), what + " " + *problem);
    return x;
  }

  // A list of exactly `n` numbers; nullopt (and an error) otherwise.
  std::optional<std::vector<double>> numbers(const YAML::Node& v, const YAML::Node& key,
                                             const FieldSpec& f, std::size_t n,
                                             const std::string& shape) {
    const std::string what = inQuotes(f.name);
    if (!v.IsSequence() || v.size() != n) {
      error(at(v, key), what + " must be " + shape + ", not " + describe(v));
      return std::nullopt;
    }
    std::vector<double> values;
    bool ok = true;
    for (const auto& item : v) {
      const auto x = number(item, key, f, what + " element");
      ok = ok && x.has_value();
      values.push_back(x.value_or(0.0));
    }
    return ok ? std::optional(values) : std::nullopt;
  }

  void value(const YAML::Node& v, const FieldSpec& f, const YAML::Node& key) {
    const std::string what = inQuotes(f.name);
    switch (f.type) {
      case FieldType::Integer: {
        const auto x = readInteger(v);
        if (!x) {
          error(at(v, key), what + " must be a whole number, not " + describe(v));
        } else if (const auto problem = rangeProblem(static_cast<double>(*x), f)) {
          error(at(v, key), what + " " + *problem);
        }
        break;
      }
      case FieldType::Number:
        number(v, key, f, what);
        break;
      case FieldType::Boolean:
        if (!readBoolean(v)) error(at(v, key), what + " must be true or false, not " + describe(v));
        break;
      case FieldType::String:
      case FieldType::Path:
        if (!v.IsScalar())
          error(at(v, key), what + " must be text, not " + describe(v));
        else if (v.Scalar().empty())
          error(at(v, key), what + " is empty: " +
                                (f.type == FieldType::Path ? "name a file" : "write some text"));
        break;
      case FieldType::Identifier:
      case FieldType::StepRef:
        if (!v.IsScalar() || !isIdentifier(v.Scalar()))
          error(at(v, key), what + " must be a step id ([a-z][a-z0-9_]*), not " + describe(v));
        break;
      case FieldType::Enum: {
        const auto s = readString(v);
        if (!s) {
          error(at(v, key), what + " must be one of " + joined(f.choices) + ", not " + describe(v));
        } else if (std::find(f.choices.begin(), f.choices.end(), *s) == f.choices.end()) {
          std::string message = "unknown " + f.name + " " + inQuotes(*s);
          if (const auto near = closestName(*s, f.choices))
            message += " (did you mean " + inQuotes(*near) + "?)";
          error(at(v, key), message + "; expected one of " + joined(f.choices));
        }
        break;
      }
      case FieldType::Point:
        numbers(v, key, f, 2, "a point [x, y]");
        break;
      case FieldType::PointList:
        if (!v.IsSequence() || v.size() < f.minItems) {
          error(at(v, key), what + " must be a list of at least " + std::to_string(f.minItems) +
                                " points [x, y], not " + describe(v));
          break;
        }
        for (const auto& item : v) numbers(item, key, f, 2, "a point [x, y]");
        break;
      case FieldType::Range:
        if (const auto r = numbers(v, key, f, 2, "a range [low, high]"); r && (*r)[0] > (*r)[1])
          error(v, what + " must have low <= high (got [" + formatNumber((*r)[0]) + ", " +
                       formatNumber((*r)[1]) + "])");
        break;
      case FieldType::Rect:
        if (const auto r = numbers(v, key, f, 4, "a rectangle [x, y, width, height]");
            r && ((*r)[2] <= 0 || (*r)[3] <= 0))
          error(v, what + " must have a positive width and height");
        break;
      case FieldType::Object:
        if (f.validatedByOwner && v.IsMap()) break;
        object(v, *f.object, what);
        break;
      case FieldType::ObjectList:
      case FieldType::StepList:
        if (!v.IsSequence() || v.size() < f.minItems) {
          error(at(v, key), what + " must be a list of at least " + std::to_string(f.minItems) +
                                " item(s), not " + describe(v));
          break;
        }
        for (const auto& item : v) {
          if (f.type == FieldType::StepList)
            step(item);
          else
            object(item, *f.object, what + " item");
        }
        break;
    }
  }

  void step(const YAML::Node& item) {
    std::vector<std::string> kinds;
    for (const auto& k : stepKinds_) kinds.push_back(k.kind);
    if (!item.IsMap()) {
      error(item, "a step must be a mapping with 'id' and 'kind', not " + describe(item));
      return;
    }
    const YAML::Node kind = item["kind"];
    if (!kind) {
      error(item, "step is missing required key 'kind' (one of " + joined(kinds) + ")");
      return;
    }
    const auto name = readString(kind);
    for (const auto& k : stepKinds_) {
      if (name && k.kind == *name) {
        object(item, k.object, k.object.name);
        return;
      }
    }
    std::string message = "unknown step kind " + (name ? inQuotes(*name) : describe(kind));
    if (name)
      if (const auto near = closestName(*name, kinds))
        message += " (did you mean " + inQuotes(*near) + "?)";
    error(kind, message + "; expected one of " + joined(kinds));
  }

  const std::filesystem::path& file_;
  Diagnostics& out_;
  const std::vector<StepKindSpec>& stepKinds_;
};

}  // namespace

std::string formatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

void validateObject(const YAML::Node& node, const ObjectSpec& spec,
                    const std::filesystem::path& file, Diagnostics& out,
                    const std::vector<StepKindSpec>& stepKinds) {
  Validator(file, out, stepKinds).object(node, spec, "the " + spec.name);
}

}  // namespace facet::config
