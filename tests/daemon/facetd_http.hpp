#pragma once
// facetd's HTTP side as a test sees it: the port it wrote to --http-port-file, and GET requests
// on 127.0.0.1 (/healthz, /metrics) whose answers the test parses.

#include <chrono>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace facet::daemon_test {

// Waits until facetd has written its port to `portFile`; nullopt on timeout.
std::optional<int> waitForHttpPort(const std::string& portFile, std::chrono::milliseconds timeout);

// The body of GET http://127.0.0.1:port/path, whatever the status; nullopt when nobody answers.
std::optional<std::string> httpGet(int port, const std::string& path);

// GET /healthz parsed; an empty object when facetd did not answer.
nlohmann::json healthz(int port);

// The value of one sample of GET /metrics, e.g. metricValue(text, "facet_archive_degraded");
// nullopt when the metric is not exposed.
std::optional<double> metricValue(const std::string& metricsText, const std::string& sample);

}  // namespace facet::daemon_test
