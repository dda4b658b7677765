#pragma once
// StepFields<P>: a step kind's keys as one table bound to the members of its parameter struct P.
// Each entry gives the validator and the JSON schema their FieldSpec and the reader its way into
// P; a documented default is taken from a default-constructed P. So the file format, the
// defaults and the struct cannot drift apart: a key exists in all three or in none.
//
//   StepFields<CircleParams> f;
//   f.number("nominal_diameter", &CircleParams::nominalDiameter, "Nominal diameter, mm.",
//            {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
//   CircleParams p; f.read(p, in);   // every key present in the step's mapping is assigned

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/types.hpp>

#include "config/step_reading.hpp"
#include "config/yaml_document.hpp"

namespace facet::config {

// Rotation searched: [low, high] degrees.
struct AngleRange {
  double low = -180.0;
  double high = 180.0;
};

struct FieldLimits {
  std::optional<double> minimum;
  std::optional<double> maximum;
  bool exclusiveMinimum = false;
  bool required = false;
};

template <class P>
class StepFields {
 public:
  using Reader = std::function<void(P&, const YAML::Node&, StepReading&)>;

  // Any key: its spec and how its value goes into P (called only when the key is present).
  StepFields& add(FieldSpec spec, Reader read) {
    entries_.push_back({std::move(spec), std::move(read)});
    return *this;
  }

  StepFields& number(std::string name, double P::*m, std::string doc, FieldLimits l = {}) {
    FieldSpec spec = limited(std::move(name), FieldType::Number, std::move(doc), l);
    if (!l.required) spec.defaultValue = defaults().*m;
    return add(std::move(spec), [m](P& p, const YAML::Node& n, StepReading&) {
      if (const auto v = readNumber(n)) p.*m = *v;
    });
  }

  // A number without a default: the member stays empty when the key is absent (a key that
  // chooses between variants, such as a caliper's length or radius).
  StepFields& number(std::string name, std::optional<double> P::*m, std::string doc,
                     FieldLimits l = {}) {
    return add(limited(std::move(name), FieldType::Number, std::move(doc), l),
               [m](P& p, const YAML::Node& n, StepReading&) {
                 if (const auto v = readNumber(n)) p.*m = *v;
               });
  }

  StepFields& integer(std::string name, int P::*m, std::string doc, FieldLimits l = {}) {
    FieldSpec spec = limited(std::move(name), FieldType::Integer, std::move(doc), l);
    if (!l.required) spec.defaultValue = defaults().*m;
    return add(std::move(spec), [m](P& p, const YAML::Node& n, StepReading&) {
      if (const auto v = readInteger(n)) p.*m = static_cast<int>(*v);
    });
  }

  // One of named values; the documented default is the name of P's default value.
  template <class E>
  StepFields& choice(std::string name, E P::*m, std::vector<std::pair<std::string, E>> names,
                     std::string doc, bool required = false) {
    FieldSpec spec{.name = std::move(name),
                   .type = FieldType::Enum,
                   .description = std::move(doc),
                   .required = required};
    for (const auto& [text, value] : names) {
      spec.choices.push_back(text);
      if (!required && value == defaults().*m) spec.defaultValue = text;
    }
    return add(std::move(spec), [m, names](P& p, const YAML::Node& n, StepReading&) {
      for (const auto& [text, value] : names)
        if (n.IsScalar() && n.Scalar() == text) p.*m = value;
    });
  }

  StepFields& point(std::string name, cv::Point2d P::*m, std::string doc, bool required) {
    return add({.name = std::move(name),
                .type = FieldType::Point,
                .description = std::move(doc),
                .required = required},
               [m](P& p, const YAML::Node& n, StepReading&) {
                 if (const auto v = readPoint(n)) p.*m = *v;
               });
  }

  StepFields& points(std::string name, std::vector<cv::Point2d> P::*m, std::string doc,
                     std::size_t minItems) {
    return add({.name = std::move(name),
                .type = FieldType::PointList,
                .description = std::move(doc),
                .required = minItems > 0,
                .minItems = minItems},
               [m](P& p, const YAML::Node& n, StepReading&) {
                 if (!n.IsSequence()) return;
                 for (const auto& item : n)
                   if (const auto v = readPoint(item)) (p.*m).push_back(*v);
               });
  }

  StepFields& rect(std::string name, std::optional<cv::Rect2d> P::*m, std::string doc) {
    return add({.name = std::move(name),
                .type = FieldType::Rect,
                .description = std::move(doc),
                .minimum = 0.0},
               [m](P& p, const YAML::Node& n, StepReading&) { p.*m = readRect(n); });
  }

  StepFields& angleRange(std::string name, AngleRange P::*m, std::string doc) {
    const AngleRange d = defaults().*m;
    return add({.name = std::move(name),
                .type = FieldType::Range,
                .description = std::move(doc),
                .minimum = -180.0,
                .maximum = 180.0,
                .defaultValue = {d.low, d.high}},
               [m](P& p, const YAML::Node& n, StepReading&) {
                 if (const auto v = readRange(n)) p.*m = {v->first, v->second};
               });
  }

  // A file, relative to the recipe; it must exist unless `mayBeMissing` (a model before training).
  StepFields& path(std::string name, std::filesystem::path P::*m, std::string doc, bool required,
                   bool mayBeMissing = false) {
    const std::string key = name;
    return add({.name = std::move(name),
                .type = FieldType::Path,
                .description = std::move(doc),
                .required = required},
               [m, key, mayBeMissing](P& p, const YAML::Node&, StepReading& in) {
                 if (const auto v = in.path(key, mayBeMissing)) p.*m = *v;
               });
  }

  // The id of an earlier step whose result offers `wanted` (StepOffers::pose, ::point, ::line).
  StepFields& stepRef(std::string name, std::optional<std::string> P::*m, bool StepOffers::*wanted,
                      std::string doc) {
    const std::string key = name;
    return add({.name = std::move(name), .type = FieldType::StepRef, .description = std::move(doc)},
               [m, key, wanted](P& p, const YAML::Node&, StepReading& in) {
                 p.*m = in.stepRef(key, wanted);
               });
  }

  StepFields& stepRef(std::string name, std::string P::*m, bool StepOffers::*wanted,
                      std::string doc) {
    const std::string key = name;
    return add({.name = std::move(name),
                .type = FieldType::StepRef,
                .description = std::move(doc),
                .required = true},
               [m, key, wanted](P& p, const YAML::Node&, StepReading& in) {
                 p.*m = in.stepRef(key, wanted).value_or("");
               });
  }

  // The specs, in the order added, for the kind's ObjectSpec.
  [[nodiscard]] std::vector<FieldSpec> specs() const {
    std::vector<FieldSpec> all;
    for (const auto& e : entries_) all.push_back(e.spec);
    return all;
  }

  // Assigns every key present in the step's mapping; absent keys keep P's defaults.
  void read(P& p, StepReading& in) const {
    for (const auto& e : entries_)
      if (const YAML::Node n = in[e.spec.name]; n) e.read(p, n, in);
  }

 private:
  struct Entry {
    FieldSpec spec;
    Reader read;
  };

  static const P& defaults() {
    static const P d{};
    return d;
  }

  static FieldSpec limited(std::string name, FieldType type, std::string doc,
                           const FieldLimits& l) {
    return {.name = std::move(name),
            .type = type,
            .description = std::move(doc),
            .required = l.required,
            .minimum = l.minimum,
            .maximum = l.maximum,
            .exclusiveMinimum = l.exclusiveMinimum};
  }

  std::vector<Entry> entries_;
};

}  // namespace facet::config
