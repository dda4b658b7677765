#include "config/step_kind.hpp"

#include <stdexcept>

namespace facet::config {

std::shared_ptr<const StepResources> StepKind::prepare(const Step& /*step*/,
                                                       StepReading& /*in*/) const {
  return nullptr;
}

std::vector<TrainedModel> StepKind::train(const Step& /*step*/) const {
  return {};
}

void StepKindRegistry::add(std::unique_ptr<StepKind> kind) {
  if (!kind) throw std::logic_error("StepKindRegistry::add: no step kind");
  if (find(kind->name()) != nullptr)
    throw std::logic_error("step kind '" + std::string(kind->name()) + "' is registered twice");
  kinds_.push_back(std::move(kind));
}

const StepKind* StepKindRegistry::find(std::string_view name) const {
  for (const auto& k : kinds_)
    if (k->name() == name) return k.get();
  return nullptr;
}

std::vector<const StepKind*> StepKindRegistry::kinds() const {
  std::vector<const StepKind*> all;
  for (const auto& k : kinds_) all.push_back(k.get());
  return all;
}

std::vector<std::string> StepKindRegistry::names() const {
  std::vector<std::string> all;
  for (const auto& k : kinds_) all.emplace_back(k->name());
  return all;
}

std::vector<StepKindSpec> StepKindRegistry::formats() const {
  std::vector<StepKindSpec> all;
  for (const auto& k : kinds_) all.push_back(k->format());
  return all;
}

std::string StepKindRegistry::namesOffering(bool StepOffers::*wanted) const {
  std::vector<std::string> fit;
  for (const auto& k : kinds_)
    if (k->offers().*wanted) fit.emplace_back(k->name());
  std::string text;
  for (std::size_t i = 0; i < fit.size(); ++i) {
    if (i > 0) text += i + 1 == fit.size() ? " or " : ", ";
    text += fit[i];
  }
  return text;
}

}  // namespace facet::config
