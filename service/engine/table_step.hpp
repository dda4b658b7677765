#pragma once
// TableStep: a step kind whose keys are one field table bound to its parameters struct, as every
// built-in kind's are. The table gives the validation, the defaults and the JSON schema, so a
// kind writes only what the table cannot say: its constructor fills fields_ and checks_ and calls
// describe(); crossCheck() reports values that contradict each other; run() measures.

#include <memory>
#include <string>

#include "config/recipe_format.hpp"
#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

template <class Params>
class TableStep : public StepUnit {
 public:
  [[nodiscard]] const config::StepKindSpec& format() const final { return format_; }
  [[nodiscard]] config::StepOffers offers() const final { return offers_; }

  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const final {
    auto params = std::make_shared<Params>();
    fields_.read(*params, in);
    crossCheck(*params, in);
    return params;
  }

 protected:
  explicit TableStep(config::StepOffers offers) : offers_(offers) {}

  // The kind's name and one line on what it does, with the keys and checks filled in by now.
  void describe(std::string kind, std::string description) {
    format_ = config::stepFormat(std::move(kind), std::move(description), fields_.specs(), checks_);
  }
  // Reports, at the key concerned, values the table accepted one by one but not together.
  virtual void crossCheck(const Params& /*params*/, config::StepReading& /*in*/) const {}

  config::StepFields<Params> fields_;
  config::ObjectSpec checks_;

 private:
  config::StepOffers offers_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
