#pragma once
// facetd's HTTP face, on 127.0.0.1 unless configured otherwise:
//   GET  /healthz          camera, PLC, recipe, archive state (200 ok/degraded, 503 down)
//   GET  /metrics          Prometheus text format
//   GET  /api/results      ?after=<part id>&limit=<n> stored parts, oldest first
//   GET  /api/last         the last part (404 before the first)
//   GET  /api/last.png     the last image with overlays
//   GET  /api/summary      shift counters, recent parts, recipe
//   POST /api/recipe       {"id": n}      switch recipe      } only when a token is configured,
//   POST /api/counters/reset               reset counters     } with "Authorization: Bearer
//   <token>"
//   GET  /, /dashboard/*   the dashboard, compiled in (dashboard_assets.hpp); files in
//                          `dashboardDir` take precedence when it is set

#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "service/daemon/station_view.hpp"

namespace httplib {
class Server;
}

namespace facet::service {

struct HttpSettings {
  std::string bindAddress = "127.0.0.1";
  int port = 8080;                     // 0 = pick a free port (see HttpServer::port())
  std::string token;                   // empty = read-only: every changing action is refused
  std::filesystem::path dashboardDir;  // static files of the dashboard (empty = none)
};

class HttpServer {
 public:
  HttpServer(StationView& station, HttpSettings settings);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds and starts serving on a thread of its own. Throws std::runtime_error when the address
  // cannot be bound.
  void start();
  void stop();
  [[nodiscard]] int port() const { return port_; }

 private:
  void routes();
  StationView& station_;
  HttpSettings settings_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace facet::service
