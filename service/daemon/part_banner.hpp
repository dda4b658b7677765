#pragma once
// The line across the top of a part's overlay picture: who the part is, the verdict and why,
// with the failing value and its band ("part 20  fail  label_angle.angle = 7.31 deg, band -5 … 5"),
// so that a picture on its own says what was wrong.

#include <string>

#include "service/engine/part_result.hpp"

namespace facet::service {

// One failed check as people read it: "name = value unit, band lower..upper", or "name not
// measured" (its step failed), or the name alone when the part has no such measurement.
std::string failedCheckText(const PartResult& part, const std::string& name);

// `who` names the part ("part 20", a serial). The first failed check with its value, "+N more"
// for the others; the error for a part that was not inspected.
std::string partBanner(const PartResult& part, const std::string& who);

}  // namespace facet::service
