#include "service/sinks/fleet_message.hpp"

#include <cmath>
#include <stdexcept>

#include "service/daemon/results_store.hpp"

namespace facet::service {

nlohmann::json fleetMessage(const std::string& station, const PartResult& part) {
  nlohmann::json message = toJson(part);
  message["station"] = station;
  message["time_us"] =
      std::chrono::duration_cast<std::chrono::microseconds>(part.time.time_since_epoch()).count();
  for (const auto& m : part.measurements) {
    if (!m.checked) continue;
    auto& v = message["values"][m.name];
    v["lower"] = m.nominal.value_or(0.0) - m.tolMinus.value_or(0.0);
    v["upper"] = m.nominal.value_or(0.0) + m.tolPlus.value_or(0.0);
  }
  return message;
}

PartResult partFromFleetMessage(const nlohmann::json& message, std::string* station) {
  try {
    PartResult p;
    *station = message.at("station").get<std::string>();
    p.partId = message.at("part_id").get<std::uint64_t>();
    p.time = std::chrono::system_clock::time_point(
        std::chrono::microseconds(message.at("time_us").get<std::int64_t>()));
    p.recipeId = message.at("recipe_id").get<int>();
    p.recipeName = message.at("recipe").get<std::string>();
    p.recipeVersion = message.at("recipe_version").get<std::string>();
    p.frameId = message.at("frame_id").get<std::uint64_t>();
    p.source = message.at("source").get<std::string>();
    p.serial = message.at("serial").get<std::string>();
    p.expectedVerdict = message.at("expected_verdict").get<std::string>();
    // Messages queued by a facetd from before `defect` have none.
    p.recordedDefect = message.value("defect", std::string());
    p.notes = message.value("notes", std::vector<std::string>());
    p.verdict = verdictFromName(message.at("verdict").get<std::string>());
    p.failedChecks = message.at("failed_checks").get<std::vector<std::string>>();
    p.error = message.at("error").get<std::string>();
    p.inspectionMs = message.at("inspection_ms").get<double>();
    for (const auto& [name, v] : message.at("values").items()) {
      Measurement m;
      m.name = name;
      m.value = v.at("value").is_null() ? std::nan("") : v.at("value").get<double>();
      m.unit = v.at("unit").get<std::string>();
      m.pass = v.at("pass").get<bool>();
      m.checked = v.contains("nominal");
      if (m.checked) {
        m.nominal = v.at("nominal").get<double>();
        m.tolMinus = v.at("tol_minus").get<double>();
        m.tolPlus = v.at("tol_plus").get<double>();
      }
      p.measurements.push_back(std::move(m));
    }
    for (const auto& [step, ms] : message.at("timings_ms").items())
      p.timings.push_back({step, ms.get<double>()});
    return p;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("fleet message: ") + e.what());
  }
}

}  // namespace facet::service
