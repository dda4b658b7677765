#pragma once
// A part's result as the station exports it: JSON (the dashboard's API, `facet results`), CSV, and
// the time format both use.

#include <chrono>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "service/engine/part_result.hpp"

namespace facet::service {

nlohmann::json toJson(const PartResult& part);
// CSV with a header row; one column per distinct measurement name across `parts`.
// `stations`, when given, holds each part's station (parts from the central database): a first
// column `station`.
std::string toCsv(const std::vector<PartResult>& parts, std::span<const std::string> stations = {});
// A list (failed checks, notes) as one text field, separated by `sep`.
std::string joinedChecks(const std::vector<std::string>& checks, char sep);
// The items of a list joinedChecks wrote (empty items dropped).
std::vector<std::string> splitList(const std::string& text, char sep);
// A part's step timings as the stores keep them in one text field: [{"step", "ms"}, ...].
std::string timingsText(const std::vector<StepTiming>& timings);
// The timings timingsText wrote; entries that are not objects are skipped, unreadable text gives
// none (a row from an older or damaged store still reads).
std::vector<StepTiming> timingsFromText(const std::string& text);
// ISO 8601 in UTC with milliseconds, e.g. 2026-11-25T20:15:03.123Z.
std::string isoTime(std::chrono::system_clock::time_point t);

}  // namespace facet::service
