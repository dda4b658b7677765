#include "service/daemon/process_capability.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "service/engine/builtin_steps.hpp"

namespace facet::service {
namespace {

void summarise(Capability& c) {
  c.count = c.values.size();
  if (c.values.empty()) return;
  double sum = 0;
  for (double v : c.values) sum += v;
  c.mean = sum / static_cast<double>(c.count);
  if (c.count >= 2) {
    double squares = 0;
    for (double v : c.values) squares += (v - c.mean) * (v - c.mean);
    c.sigma = std::sqrt(squares / static_cast<double>(c.count - 1));
  }
  if (!c.lower || !c.upper || !(c.sigma > 0)) return;
  const NaturalBounds natural = naturalBounds(c.name, c.unit);
  const bool lowerIsBound = natural.lower && *c.lower <= *natural.lower;
  const bool upperIsBound = natural.upper && *c.upper >= *natural.upper;
  if (lowerIsBound && upperIsBound) return;  // nothing the process can miss
  if (lowerIsBound) {
    c.index = "Cpu";
    c.cpk = (*c.upper - c.mean) / (3 * c.sigma);
  } else if (upperIsBound) {
    c.index = "Cpl";
    c.cpk = (c.mean - *c.lower) / (3 * c.sigma);
  } else {
    c.index = "Cpk";
    c.cp = (*c.upper - *c.lower) / (6 * c.sigma);
    c.cpk = std::min(*c.upper - c.mean, c.mean - *c.lower) / (3 * c.sigma);
  }
}

}  // namespace

NaturalBounds naturalBounds(const std::string& name, const std::string& unit) {
  NaturalBounds bounds;
  const std::string value = name.substr(name.rfind('.') + 1);
  // The check tables of facet's step kinds; a value name means the same quantity in each.
  static const config::StepKindRegistry kinds = builtinSteps();
  for (const config::StepKind* kind : kinds.kinds()) {
    const config::FieldSpec* checks = kind->format().object.find("checks");
    if (checks == nullptr || checks->object == nullptr) continue;
    const config::FieldSpec* field = checks->object->find(value);
    if (field == nullptr) continue;
    if (field->minimum) bounds.lower = *field->minimum;
    if (field->quantity == config::Quantity::Score) bounds.upper = 1.0;
  }
  if (unit == "score") bounds.upper = 1.0;
  return bounds;
}

std::vector<Capability> processCapability(const std::vector<PartResult>& parts) {
  std::vector<Capability> out;
  std::map<std::string, std::size_t> index;
  for (const auto& part : parts) {
    for (const auto& m : part.measurements) {
      auto [it, fresh] = index.try_emplace(m.name, out.size());
      if (fresh) {
        out.push_back({});
        out.back().name = m.name;
        out.back().unit = m.unit;
      }
      Capability& c = out[it->second];
      // The band of the newest part that carries one (the recipe is the same for the series).
      if (m.checked && m.nominal) {
        c.nominal = *m.nominal;
        c.lower = *m.nominal - m.tolMinus.value_or(0.0);
        c.upper = *m.nominal + m.tolPlus.value_or(0.0);
      }
      if (std::isfinite(m.value)) c.values.push_back(m.value);
    }
  }
  for (auto& c : out) summarise(c);
  return out;
}

}  // namespace facet::service
