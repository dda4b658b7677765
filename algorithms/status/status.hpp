#pragma once
// Status<Cause>: the one way an algorithm result says whether it worked. Each module keeps its
// own Cause enum (domain names, value 0 = it worked, a snake_case toString() for JSON and logs);
// a result carries `Status<ItsCause> status` and never a made-up value when !status.ok().

#include <string>
#include <utility>

namespace facet {

template <class Cause>
struct Status {
  Cause cause{};        // Cause{} when it worked
  std::string message;  // for the engineer, when it did not; empty when it worked

  [[nodiscard]] bool ok() const { return cause == Cause{}; }

  [[nodiscard]] static Status failed(Cause cause, std::string message = {}) {
    return {cause, std::move(message)};
  }
};

}  // namespace facet
