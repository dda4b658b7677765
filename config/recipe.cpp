#include "config/recipe.hpp"

namespace facet::config {

const Check* Step::check(std::string_view checkName) const {
  for (const auto& c : checks)
    if (c.name == checkName) return &c;
  return nullptr;
}

const Step* Recipe::step(std::string_view stepId) const {
  for (const auto& s : steps)
    if (s.id == stepId) return &s;
  return nullptr;
}

std::vector<std::pair<const Check*, const Step*>> Recipe::plcOutputs() const {
  std::vector<std::pair<const Check*, const Step*>> out;
  for (const auto& s : steps)
    for (const auto& c : s.checks)
      if (c.plc) out.emplace_back(&c, &s);
  return out;
}

std::string_view toString(Unit unit) {
  switch (unit) {
    case Unit::Millimetre:
      return "mm";
    case Unit::Degree:
      return "deg";
    case Unit::Pixel:
      return "px";
    case Unit::None:
      return "";
  }
  return "?";
}

}  // namespace facet::config
