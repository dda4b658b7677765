#include "service/daemon/part_banner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace facet::service {
namespace {

std::string number(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", value);
  return buf;
}

}  // namespace

std::string failedCheckText(const PartResult& part, const std::string& name) {
  const auto m = std::find_if(part.measurements.begin(), part.measurements.end(),
                              [&](const Measurement& x) { return x.name == name; });
  if (m == part.measurements.end()) return name;
  if (!std::isfinite(m->value)) return name + " not measured";
  const std::string unit = m->unit == "score" || m->unit == "count" ? "" : " " + m->unit;
  std::string text = name + " = " + number(m->value) + unit;
  if (m->nominal)
    text += ", band " + number(*m->nominal - m->tolMinus.value_or(0)) + ".." +
            number(*m->nominal + m->tolPlus.value_or(0));
  return text;
}

std::string partBanner(const PartResult& part, const std::string& who) {
  std::string banner = who + "  " + verdictName(part.verdict);
  if (part.verdict == Verdict::Error && !part.error.empty()) return banner + "  " + part.error;
  if (part.failedChecks.empty()) return banner;
  banner += "  " + failedCheckText(part, part.failedChecks.front());
  if (part.failedChecks.size() > 1)
    banner += "  +" + std::to_string(part.failedChecks.size() - 1) + " more";
  return banner;
}

}  // namespace facet::service
