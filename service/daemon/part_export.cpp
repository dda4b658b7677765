#include "service/daemon/part_export.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <set>
#include <sstream>

namespace facet::service {

std::string isoTime(std::chrono::system_clock::time_point t) {
  const std::time_t secs = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count() % 1000;
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

nlohmann::json toJson(const PartResult& p) {
  nlohmann::json values = nlohmann::json::object();
  for (const auto& m : p.measurements) {
    nlohmann::json v{{"value", std::isfinite(m.value) ? nlohmann::json(m.value) : nullptr},
                     {"unit", m.unit},
                     {"pass", m.pass}};
    if (m.checked) {
      v["nominal"] = m.nominal.value_or(0.0);
      v["tol_minus"] = m.tolMinus.value_or(0.0);
      v["tol_plus"] = m.tolPlus.value_or(0.0);
    }
    values[m.name] = v;
  }
  nlohmann::json timings = nlohmann::json::object();
  for (const auto& t : p.timings) timings[t.step] = t.ms;
  return {{"part_id", p.partId},
          {"time", isoTime(p.time)},
          {"recipe_id", p.recipeId},
          {"recipe", p.recipeName},
          {"recipe_version", p.recipeVersion},
          {"frame_id", p.frameId},
          {"source", p.source},
          {"serial", p.serial},
          {"expected_verdict", p.expectedVerdict},
          {"defect", p.recordedDefect},
          {"verdict", verdictName(p.verdict)},
          {"failed_checks", p.failedChecks},
          {"error", p.error},
          {"notes", p.notes},
          {"inspection_ms", p.inspectionMs},
          {"values", values},
          {"timings_ms", timings}};
}

std::string toCsv(const std::vector<PartResult>& parts, std::span<const std::string> stations) {
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const auto& p : parts)
    for (const auto& m : p.measurements)
      if (seen.insert(m.name).second) names.push_back(m.name);
  auto quote = [](const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  };
  std::ostringstream out;
  // expected_verdict and defect (of recorded parts) came later: after the first ten columns, so
  // that a script reading columns by position still finds those where they were.
  if (!stations.empty()) out << "station,";
  out << "part_id,time,recipe_id,recipe,frame_id,serial,verdict,failed_checks,error,inspection_ms,"
         "expected_verdict,defect";
  for (const auto& n : names) out << ',' << quote(n);
  out << '\n';
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const PartResult& p = parts[i];
    if (!stations.empty()) out << quote(stations[i]) << ',';
    out << p.partId << ',' << isoTime(p.time) << ',' << p.recipeId << ',' << quote(p.recipeName)
        << ',' << p.frameId << ',' << quote(p.serial) << ',' << verdictName(p.verdict) << ','
        << quote(joinedChecks(p.failedChecks, ';')) << ',' << quote(p.error) << ','
        << p.inspectionMs << ',' << quote(p.expectedVerdict) << ',' << quote(p.recordedDefect);
    std::map<std::string, double> byName;
    for (const auto& m : p.measurements) byName[m.name] = m.value;
    for (const auto& n : names) {
      out << ',';
      if (auto it = byName.find(n); it != byName.end() && std::isfinite(it->second))
        out << it->second;
    }
    out << '\n';
  }
  return out.str();
}

std::vector<std::string> splitList(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string timingsText(const std::vector<StepTiming>& timings) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& t : timings) out.push_back({{"step", t.step}, {"ms", t.ms}});
  return out.dump();
}

std::vector<StepTiming> timingsFromText(const std::string& text) {
  std::vector<StepTiming> out;
  const auto parsed = nlohmann::json::parse(text, nullptr, false);
  if (!parsed.is_array()) return out;
  for (const auto& t : parsed)
    if (t.is_object()) out.push_back({t.value("step", ""), t.value("ms", 0.0)});
  return out;
}

std::string joinedChecks(const std::vector<std::string>& items, char sep) {
  std::string out;
  for (const auto& s : items) {
    if (!out.empty()) out += sep;
    out += s;
  }
  return out;
}

}  // namespace facet::service
