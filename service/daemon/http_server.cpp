#include "service/daemon/http_server.hpp"

#include <httplib.h>

#include <stdexcept>

#include "service/daemon/dashboard_assets.hpp"
#include "service/daemon/results_store.hpp"

namespace facet::service {
namespace {

void sendJson(httplib::Response& res, const nlohmann::json& body, int status = 200) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

std::size_t parseCount(const httplib::Request& req, const char* key, std::size_t fallback,
                       std::size_t max) {
  if (!req.has_param(key)) return fallback;
  try {
    const auto v = std::stoull(req.get_param_value(key));
    return std::min<std::size_t>(v, max);
  } catch (const std::exception&) {
    return fallback;
  }
}

// Compares in time that depends only on the lengths, so that response times do not reveal how
// much of a guessed token was right.
bool sameSecret(const std::string& given, const std::string& expected) {
  unsigned char diff = given.size() == expected.size() ? 0 : 1;
  for (std::size_t i = 0; i < given.size(); ++i)
    diff |= static_cast<unsigned char>(given[i] ^
                                       expected[i % std::max<std::size_t>(1, expected.size())]);
  return diff == 0;
}

}  // namespace

HttpServer::HttpServer(StationView& station, HttpSettings settings)
    : station_(station),
      settings_(std::move(settings)),
      server_(std::make_unique<httplib::Server>()) {
  // SO_REUSEADDR only: httplib's default also sets SO_REUSEPORT, which would let a second
  // facetd share the port silently instead of failing to start.
  server_->set_socket_options([](int sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  routes();
}

HttpServer::~HttpServer() {
  stop();
}

void HttpServer::routes() {
  auto& s = *server_;
  s.Get("/healthz", [this](const httplib::Request&, httplib::Response& res) {
    const auto health = station_.health();
    sendJson(res, health, health.value("status", "down") == "down" ? 503 : 200);
  });
  s.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(station_.metricsText(), "text/plain; version=0.0.4");
  });
  s.Get("/api/results", [this](const httplib::Request& req, httplib::Response& res) {
    const auto after = parseCount(req, "after", 0, std::numeric_limits<std::size_t>::max());
    const auto limit = parseCount(req, "limit", 100, 10000);
    nlohmann::json parts = nlohmann::json::array();
    for (const auto& p : station_.storedParts(after, limit)) parts.push_back(toJson(p));
    sendJson(res, {{"parts", parts}});
  });
  s.Get("/api/last", [this](const httplib::Request&, httplib::Response& res) {
    const auto parts = station_.recentParts(1);
    if (parts.empty()) return sendJson(res, {{"error", "no part inspected yet"}}, 404);
    sendJson(res, toJson(parts.back()));
  });
  s.Get("/api/last.png", [this](const httplib::Request&, httplib::Response& res) {
    const auto png = station_.lastOverlayPng();
    if (png.empty()) return sendJson(res, {{"error", "no image yet"}}, 404);
    res.set_header("Cache-Control", "no-store");
    res.set_content(std::string(png.begin(), png.end()), "image/png");
  });
  s.Get("/api/summary", [this](const httplib::Request&, httplib::Response& res) {
    sendJson(res, station_.summary());
  });
  // Changing actions: refused unless a token is configured and presented.
  auto authorised = [this](const httplib::Request& req, httplib::Response& res) {
    if (settings_.token.empty()) {
      sendJson(res, {{"error", "read-only station: no token configured"}}, 403);
      return false;
    }
    if (!sameSecret(req.get_header_value("Authorization"), "Bearer " + settings_.token)) {
      sendJson(res, {{"error", "missing or wrong token"}}, 401);
      return false;
    }
    return true;
  };
  s.Post("/api/recipe", [this, authorised](const httplib::Request& req, httplib::Response& res) {
    if (!authorised(req, res)) return;
    const auto body = nlohmann::json::parse(req.body, nullptr, false);
    if (!body.is_object() || !body.contains("id") || !body["id"].is_number_integer())
      return sendJson(res, {{"error", "expected {\"id\": <recipe number>}"}}, 400);
    const auto outcome = station_.selectRecipe(body["id"].get<int>());
    sendJson(res, {{"ok", outcome.ok}, {"message", outcome.message}}, outcome.ok ? 200 : 409);
  });
  s.Post("/api/counters/reset",
         [this, authorised](const httplib::Request& req, httplib::Response& res) {
           if (!authorised(req, res)) return;
           const auto outcome = station_.resetCounters();
           sendJson(res, {{"ok", outcome.ok}, {"message", outcome.message}});
         });
  // The dashboard compiled into the binary; a configured dashboardDir is served first (its
  // files override these, e.g. while working on the page).
  auto sendAsset = [](const DashboardAsset* asset, httplib::Response& res) {
    if (!asset) return sendJson(res, {{"error", "no such dashboard file"}}, 404);
    res.set_content(std::string(asset->body), std::string(asset->contentType).c_str());
  };
  s.Get("/", [sendAsset](const httplib::Request&, httplib::Response& res) {
    sendAsset(findDashboardAsset("index.html"), res);
  });
  s.Get("/dashboard/([A-Za-z0-9_.-]+)",
        [sendAsset](const httplib::Request& req, httplib::Response& res) {
          sendAsset(findDashboardAsset(req.matches[1].str()), res);
        });
  if (!settings_.dashboardDir.empty()) s.set_mount_point("/", settings_.dashboardDir.string());
}

void HttpServer::start() {
  if (settings_.port == 0) {
    port_ = server_->bind_to_any_port(settings_.bindAddress.c_str());
    if (port_ <= 0)
      throw std::runtime_error("http: cannot bind " + settings_.bindAddress + " (any port)");
  } else {
    if (!server_->bind_to_port(settings_.bindAddress.c_str(), settings_.port))
      throw std::runtime_error("http: cannot bind " + settings_.bindAddress + ":" +
                               std::to_string(settings_.port));
    port_ = settings_.port;
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  // stop() is only effective once the server runs: wait for it so start-then-stop never hangs.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!server_->is_running() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void HttpServer::stop() {
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace facet::service
