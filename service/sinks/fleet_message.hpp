#pragma once
// The result of one part as it leaves the station for the fleet: the JSON published on MQTT and
// kept in the outboxes. It is the results store's JSON (toJson: part id, time, recipe and
// version, verdict, failed checks, error cause, every value with unit and pass) plus the
// station's name, the time in microseconds and each checked value's limits.
//
// Example (abridged):
//   {"station": "line3-cam1", "part_id": 412, "time": "2026-11-29T21:03:07.125Z",
//    "time_us": 1795986187125331, "recipe_id": 1, "recipe": "flange", "recipe_version": "9c1e..",
//    "verdict": "fail", "failed_checks": ["bore.diameter"], "error": "",
//    "values": {"bore.diameter": {"value": 12.07, "unit": "mm", "pass": false, "nominal": 12.0,
//                                 "tol_minus": 0.05, "tol_plus": 0.05, "lower": 11.95,
//                                 "upper": 12.05}}, ...}

#include <string>

#include <nlohmann/json.hpp>

#include "service/engine/part_result.hpp"

namespace facet::service {

nlohmann::json fleetMessage(const std::string& station, const PartResult& part);

// The part back from its message (what the PostgreSQL sink stores); `station` receives the
// station's name. Throws std::runtime_error when the message lacks a field.
PartResult partFromFleetMessage(const nlohmann::json& message, std::string* station);

}  // namespace facet::service
