// PlcLink against facet's own PLC simulator (the one `facet plc-sim` runs): triggers at a rate,
// every result read back and acknowledged; and free run.
#include <gtest/gtest.h>

#include <mutex>
#include <thread>

#include "plc/plc_link.hpp"
#include "plc/plc_simulator.hpp"
#include "plc/register_map_yaml.hpp"

namespace facet::plc {
namespace {

using namespace std::chrono_literals;

RegisterMap exampleMap() {
  return loadRegisterMap(std::string(FACET_SOURCE_DIR) +
                         "/tests/plc/data/station_register_map.yaml");
}

PlcSettings settingsFor(int port, HandshakeMode mode) {
  PlcSettings settings;
  settings.port = port;
  settings.mode = mode;
  settings.pollPeriod = 1ms;
  settings.reconnectInitial = 20ms;
  return settings;
}

struct Received {
  std::mutex mutex;
  std::vector<ReceivedResult> results;
  std::size_t size() {
    std::lock_guard lock(mutex);
    return results.size();
  }
};

double valueFor(int i) {
  return 10.0 + 0.25 * i;
}

TEST(PlcSimulator, TriggersAtARateAndReadsEveryResult) {
  PlcSimulatorOptions options;
  options.triggerRate = 100.0;
  PlcSimulator sim(exampleMap(), options);
  Received received;
  sim.onResult([&](const ReceivedResult& r) {
    std::lock_guard lock(received.mutex);
    received.results.push_back(r);
  });
  PlcLink link(exampleMap(), settingsFor(sim.port(), HandshakeMode::Triggered));
  link.setActiveRecipe(3);
  link.setReady(false);
  link.start();
  sim.start();
  // Not ready: the rate raises nothing (a daemon still starting would only miss its triggers).
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(sim.stats().triggersRaised, 0u);
  link.setReady(true);
  constexpr int kParts = 10;
  for (int i = 0; i < kParts; ++i) {
    const auto trigger = link.waitTrigger(5s);
    ASSERT_TRUE(trigger) << "trigger " << i;
    InspectionResult r;
    r.partId = "sim-" + std::to_string(i);
    r.pass = i % 3 != 0;
    r.values = {{"diameter_mm", valueFor(i)},
                {"offset_x_mm", -0.5},
                {"offset_y_mm", 1.25},
                {"angle_deg", -90.0 + i},
                {"score", 0.875}};
    ASSERT_TRUE(link.publish(r));
  }
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (received.size() < kParts && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  sim.stop();
  ASSERT_GE(received.size(), std::size_t(kParts));
  for (int i = 0; i < kParts; ++i) {
    const auto& r = received.results[i];
    EXPECT_EQ(r.inspectionCounter, i + 1);
    EXPECT_EQ(r.pass, i % 3 != 0);
    EXPECT_FLOAT_EQ(r.values.at("diameter_mm"), valueFor(i));
    EXPECT_DOUBLE_EQ(r.values.at("offset_x_mm"), -0.5);
    EXPECT_DOUBLE_EQ(r.values.at("offset_y_mm"), 1.25);
    EXPECT_FLOAT_EQ(r.values.at("angle_deg"), -90.0 + i);
    EXPECT_DOUBLE_EQ(r.values.at("score"), 0.875);
  }
  EXPECT_GE(sim.stats().triggersRaised, std::uint64_t(kParts));
  EXPECT_EQ(link.stats().dropped, 0u);
  EXPECT_EQ(describe(received.results[0]).rfind("result #1 FAIL error=0 angle_deg=-90", 0), 0u)
      << describe(received.results[0]);
}

TEST(PlcSimulator, FreeRunReportsEachCounter) {
  PlcSimulatorOptions options;
  options.mode = HandshakeMode::FreeRun;
  PlcSimulator sim(exampleMap(), options);
  Received received;
  sim.onResult([&](const ReceivedResult& r) {
    std::lock_guard lock(received.mutex);
    received.results.push_back(r);
  });
  sim.start();
  PlcLink link(exampleMap(), settingsFor(sim.port(), HandshakeMode::FreeRun));
  link.start();
  for (int i = 0; i < 5; ++i) {
    InspectionResult r;
    r.partId = "free-" + std::to_string(i);
    r.pass = true;
    r.values = {{"diameter_mm", valueFor(i)},
                {"offset_x_mm", 0.0},
                {"offset_y_mm", 0.0},
                {"angle_deg", 0.0},
                {"score", 1.0}};
    ASSERT_TRUE(link.publish(r));
    // The simulator scans for a changed counter: a result written before it saw the previous
    // one would hide that one (a link thread starved on a loaded machine writes two in a row).
    // Each result is published once the previous one was seen; the values are checked below.
    const auto seen = std::chrono::steady_clock::now() + 5s;
    while (received.size() < static_cast<std::size_t>(i + 1) &&
           std::chrono::steady_clock::now() < seen)
      std::this_thread::sleep_for(1ms);
  }
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (received.size() < 5 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  sim.stop();
  ASSERT_EQ(received.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(received.results[i].inspectionCounter, i + 1);
    EXPECT_FLOAT_EQ(received.results[i].values.at("diameter_mm"), valueFor(i));
  }
}

}  // namespace
}  // namespace facet::plc
