// The HTTP layer against a real socket on 127.0.0.1 with a scripted station behind it.
#include <httplib.h>

#include <gtest/gtest.h>

#include "service/daemon/http_server.hpp"
#include "service/daemon/results_store.hpp"

namespace facet::service {
namespace {

class ScriptedStation : public StationView {
 public:
  nlohmann::json health() const override { return {{"status", status}}; }
  std::string metricsText() const override { return "facet_parts_total 7\n"; }
  std::vector<PartResult> recentParts(std::size_t) const override { return parts; }
  std::vector<PartResult> storedParts(std::uint64_t after, std::size_t limit) const override {
    std::vector<PartResult> out;
    for (const auto& p : parts)
      if (p.partId > after && out.size() < limit) out.push_back(p);
    return out;
  }
  std::vector<unsigned char> lastOverlayPng() const override { return png; }
  nlohmann::json summary() const override { return {{"pass", 1}}; }
  ActionOutcome selectRecipe(int id) override {
    selected = id;
    return {true, "switching to " + std::to_string(id)};
  }
  ActionOutcome resetCounters() override { return {true, "reset"}; }

  std::string status = "ok";
  std::vector<PartResult> parts;
  std::vector<unsigned char> png;
  int selected = -1;
};

TEST(HttpServer, ServesHealthMetricsAndResults) {
  ScriptedStation station;
  HttpServer server(station, {.bindAddress = "127.0.0.1", .port = 0});
  server.start();
  httplib::Client client("127.0.0.1", server.port());

  auto health = client.Get("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  station.status = "down";
  EXPECT_EQ(client.Get("/healthz")->status, 503);

  auto metrics = client.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_EQ(metrics->body, "facet_parts_total 7\n");

  EXPECT_EQ(client.Get("/api/last")->status, 404);
  EXPECT_EQ(client.Get("/api/last.png")->status, 404);
  for (std::uint64_t id = 1; id <= 3; ++id) {
    PartResult p;
    p.partId = id;
    p.verdict = id == 2 ? Verdict::Fail : Verdict::Pass;
    station.parts.push_back(p);
  }
  station.png = {0x89, 'P', 'N', 'G'};
  auto last = client.Get("/api/last");
  ASSERT_EQ(last->status, 200);
  EXPECT_EQ(nlohmann::json::parse(last->body)["part_id"], 3);
  auto results = client.Get("/api/results?after=1&limit=1");
  const auto body = nlohmann::json::parse(results->body);
  ASSERT_EQ(body["parts"].size(), 1u);
  EXPECT_EQ(body["parts"][0]["verdict"], "fail");
  auto png = client.Get("/api/last.png");
  EXPECT_EQ(png->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(png->body.size(), 4u);
  server.stop();
}

TEST(HttpServer, ChangingActionsNeedTheConfiguredToken) {
  ScriptedStation station;
  {
    HttpServer readOnly(station, {.bindAddress = "127.0.0.1", .port = 0});
    readOnly.start();
    httplib::Client client("127.0.0.1", readOnly.port());
    auto res = client.Post("/api/recipe", R"({"id": 2})", "application/json");
    EXPECT_EQ(res->status, 403);
    EXPECT_EQ(station.selected, -1);
  }
  HttpServer guarded(station, {.bindAddress = "127.0.0.1", .port = 0, .token = "s3cret"});
  guarded.start();
  httplib::Client client("127.0.0.1", guarded.port());
  EXPECT_EQ(client.Post("/api/recipe", R"({"id": 2})", "application/json")->status, 401);
  EXPECT_EQ(station.selected, -1);
  httplib::Headers auth{{"Authorization", "Bearer s3cret"}};
  EXPECT_EQ(client.Post("/api/recipe", auth, R"({"id": "x"})", "application/json")->status, 400);
  EXPECT_EQ(client.Post("/api/recipe", auth, R"({"id": 2})", "application/json")->status, 200);
  EXPECT_EQ(station.selected, 2);
  EXPECT_EQ(client.Post("/api/counters/reset", auth, "", "text/plain")->status, 200);
}

TEST(HttpServer, PortInUseIsAClearError) {
  ScriptedStation station;
  HttpServer first(station, {.bindAddress = "127.0.0.1", .port = 0});
  first.start();
  HttpServer second(station, {.bindAddress = "127.0.0.1", .port = first.port()});
  EXPECT_THROW(second.start(), std::runtime_error);
}

}  // namespace
}  // namespace facet::service
