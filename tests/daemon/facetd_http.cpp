#include "tests/daemon/facetd_http.hpp"

#include <httplib.h>

#include <fstream>
#include <sstream>
#include <thread>

namespace facet::daemon_test {

std::optional<int> waitForHttpPort(const std::string& portFile, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    int port = 0;
    if (std::ifstream(portFile) >> port && port > 0) return port;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return std::nullopt;
}

std::optional<std::string> httpGet(int port, const std::string& path) {
  httplib::Client client("127.0.0.1", port);
  client.set_connection_timeout(std::chrono::seconds(2));
  client.set_read_timeout(std::chrono::seconds(5));
  const auto reply = client.Get(path);
  if (!reply) return std::nullopt;
  return reply->body;
}

nlohmann::json healthz(int port) {
  const auto body = httpGet(port, "/healthz");
  if (!body) return nlohmann::json::object();
  return nlohmann::json::parse(*body, nullptr, false);
}

std::optional<double> metricValue(const std::string& metricsText, const std::string& sample) {
  std::istringstream in(metricsText);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(sample + " ", 0) != 0) continue;
    return std::stod(line.substr(sample.size() + 1));
  }
  return std::nullopt;
}

}  // namespace facet::daemon_test
