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

}  // namespace facet::service
