#include "service/batch/golden_set.hpp"

#include <cmath>
#include <filesystem>

#include <spdlog/fmt/fmt.h>
#include <nlohmann/json.hpp>

namespace facet::service {
namespace {

std::string got(const PartResult& p) {
  std::string text = verdictName(p.verdict);
  if (p.verdict == Verdict::Error) return text + " (" + p.error + ")";
  if (!p.failedChecks.empty()) {
    text += " (";
    for (std::size_t i = 0; i < p.failedChecks.size(); ++i)
      text += (i ? ", " : "") + p.failedChecks[i];
    text += ")";
  }
  return text;
}

}  // namespace

std::vector<GoldenMismatch> compareWithGolden(const PartResult& part,
                                              const SidecarMetadata::Entries& sidecar) {
  std::vector<GoldenMismatch> out;
  const std::string file = std::filesystem::path(part.source).filename().string();
  auto mismatch = [&](std::string check, std::string expected, std::string found) {
    out.push_back({file, part.serial, std::move(check), std::move(expected), std::move(found)});
  };
  const auto verdict = sidecar.find("expected_verdict");
  if (verdict == sidecar.end())
    mismatch("verdict", "(no expected_verdict in the sidecar)", got(part));
  else if (verdict->second != "pass" && verdict->second != "fail")
    mismatch("verdict", fmt::format("'{}' (must be pass or fail)", verdict->second), got(part));
  else if (verdict->second != verdictName(part.verdict))
    mismatch("verdict", verdict->second, got(part));

  const auto values = sidecar.find("expected_values");
  if (values == sidecar.end()) return out;
  const auto expected = nlohmann::json::parse(values->second, nullptr, false);
  if (!expected.is_object()) {
    mismatch("expected_values", "an object {name: {value, tolerance}}", "malformed sidecar");
    return out;
  }
  for (const auto& [name, spec] : expected.items()) {
    if (!spec.is_object() || !spec.contains("value") || !spec["value"].is_number() ||
        (spec.contains("tolerance") && !spec["tolerance"].is_number())) {
      mismatch(name, "{value: number, tolerance: number}", "malformed sidecar");
      continue;
    }
    const ExpectedValue want{spec["value"].get<double>(), spec.value("tolerance", 0.0)};
    const std::string wanted = fmt::format("{:.4f} +- {:.4f}", want.value, want.tolerance);
    const Measurement* m = nullptr;
    for (const auto& candidate : part.measurements)
      if (candidate.name == name) m = &candidate;
    if (!m || !std::isfinite(m->value))
      mismatch(name, wanted, "not measured");
    else if (std::abs(m->value - want.value) > want.tolerance)
      mismatch(name, wanted, fmt::format("{:.4f} ({:+.4f})", m->value, m->value - want.value));
  }
  return out;
}

}  // namespace facet::service
