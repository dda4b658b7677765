#include "service/engine/part_result.hpp"

namespace facet::service {

const char* verdictName(Verdict v) {
  switch (v) {
    case Verdict::Pass:
      return "pass";
    case Verdict::Fail:
      return "fail";
    case Verdict::Error:
      return "error";
  }
  return "error";
}

Verdict verdictFromName(std::string_view name) {
  if (name == "pass") return Verdict::Pass;
  if (name == "fail") return Verdict::Fail;
  return Verdict::Error;
}

}  // namespace facet::service
