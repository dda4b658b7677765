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
// ISO 8601 in UTC with milliseconds, e.g. 2026-11-25T20:15:03.123Z.
std::string isoTime(std::chrono::system_clock::time_point t);

}  // namespace facet::service
