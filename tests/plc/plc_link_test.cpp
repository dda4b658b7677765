// PlcLink against an independent PLC: a pymodbus TCP server with a small PLC program
// (tests/plc/pymodbus_plc.py) on 127.0.0.1. The peer decodes every register with Python's
// struct, so word orders are checked by a second implementation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <modbus.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include "plc/plc_link.hpp"
#include "plc/register_encoding.hpp"
#include "plc/register_map_yaml.hpp"
#include "tests/plc/pymodbus_peer.hpp"

namespace facet::plc {
namespace {

using namespace std::chrono_literals;
using test::PymodbusPlc;
using ::testing::HasSubstr;

constexpr WordOrder kOrders[] = {WordOrder::ABCD, WordOrder::CDAB, WordOrder::BADC,
                                 WordOrder::DCBA};

Location coil(int address) {
  return {Table::Coil, address, -1, ""};
}
Location reg(int address, int bit = -1) {
  return {Table::HoldingRegister, address, bit, ""};
}

// Every status and control signal, flags as coils and as register bits, and one result per
// type and word order. `base` shifts every address (one-based maps write wire address + 1).
RegisterMap fullMap(int base = 0) {
  RegisterMap map;
  map.addressBase = base;
  map.control.trigger = coil(0 + base);
  map.control.resultAck = coil(1 + base);
  map.control.recipeSelect = reg(5 + base);
  map.status.ready = coil(8 + base);
  map.status.busy = coil(9 + base);
  map.status.resultValid = coil(10 + base);
  map.status.pass = reg(19 + base, 2);
  map.status.completedToggle = reg(19 + base, 5);
  map.status.missedTrigger = coil(13 + base);
  map.status.error = reg(19 + base, 0);
  map.status.errorCode = reg(20 + base);
  map.status.heartbeat = reg(21 + base);
  map.status.inspectionCounter = reg(22 + base);
  map.status.activeRecipe = reg(23 + base);
  int address = 100 + base;
  map.results.push_back({"i16", address++, ValueType::Int16, 1.0, WordOrder::ABCD, ""});
  map.results.push_back({"s16", address++, ValueType::ScaledInt16, 100.0, WordOrder::ABCD, ""});
  for (const auto order : kOrders) {
    const std::string o = toString(order);
    map.results.push_back({"i32_" + o, address, ValueType::Int32, 1.0, order, ""});
    map.results.push_back({"s32_" + o, address + 2, ValueType::ScaledInt32, 1000.0, order, ""});
    map.results.push_back({"f32_" + o, address + 4, ValueType::Float32, 1.0, order, ""});
    address += 6;
  }
  return map;
}

PlcSettings fastSettings(int port) {
  PlcSettings settings;
  settings.port = port;
  settings.pollPeriod = 1ms;
  settings.responseTimeout = 300ms;
  settings.reconnectInitial = 20ms;
  settings.reconnectMax = 200ms;
  settings.heartbeatPeriod = 20ms;
  return settings;
}

InspectionResult sampleResult(const RegisterMap& map, int variant, const std::string& part) {
  InspectionResult r;
  r.partId = part;
  r.pass = variant % 2 == 0;
  r.errorCode = variant % 2 == 0 ? 0 : 40 + variant;
  const double sign = variant % 2 == 0 ? 1.0 : -1.0;
  for (const auto& output : map.results) {
    switch (output.type) {
      case ValueType::Int16:
        r.values[output.name] = sign * (1234 + variant);
        break;
      case ValueType::ScaledInt16:
        r.values[output.name] = sign * 12.34;
        break;
      case ValueType::Int32:
        r.values[output.name] = sign * (16909060.0 + variant);
        break;
      case ValueType::ScaledInt32:
        r.values[output.name] = sign * 123456.789;
        break;
      case ValueType::Float32:
        r.values[output.name] = sign * (3.14159265 + variant);
        break;
    }
  }
  return r;
}

using Float32Getter = float (*)(const std::uint16_t*);
Float32Getter libmodbusGetter(WordOrder order) {
  switch (order) {
    case WordOrder::ABCD:
      return modbus_get_float_abcd;
    case WordOrder::CDAB:
      return modbus_get_float_cdab;
    case WordOrder::BADC:
      return modbus_get_float_badc;
    case WordOrder::DCBA:
      return modbus_get_float_dcba;
  }
  return modbus_get_float_abcd;
}

// Checks one result as the pymodbus PLC decoded it against what was published.
void expectDelivered(const RegisterMap& map, const InspectionResult& sent,
                     const nlohmann::json& got, int counter) {
  EXPECT_EQ(got["counter"], counter);
  EXPECT_EQ(got["pass"], sent.pass);
  EXPECT_EQ(got["error"], sent.errorCode != 0);
  EXPECT_EQ(got["error_code"], sent.errorCode);
  for (const auto& output : map.results) {
    const double value = sent.values.at(output.name);
    const double decoded = got["values"][output.name];
    const auto raw = got["raw"][output.name].get<std::vector<std::uint16_t>>();
    const auto encoded = encodeValue(output, value);
    // The PLC's registers hold exactly our words, and Python's struct decodes them to the value.
    for (int i = 0; i < encoded.count; ++i)
      EXPECT_EQ(raw.at(i), encoded.words[i]) << output.name << " word " << i;
    if (output.type == ValueType::Float32) {
      EXPECT_EQ(static_cast<float>(decoded), static_cast<float>(value)) << output.name;
      EXPECT_EQ(libmodbusGetter(output.wordOrder)(raw.data()), static_cast<float>(value))
          << output.name << " (libmodbus getter)";
    } else if (output.type == ValueType::ScaledInt16 || output.type == ValueType::ScaledInt32) {
      EXPECT_NEAR(decoded, value, 0.5 / output.factor) << output.name;
    } else {
      EXPECT_EQ(decoded, value) << output.name;
    }
  }
}

bool waitUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(2ms);
  }
  return done();
}

// Counts events of one kind; used inside PymodbusPlc::waitFor predicates (which hold its lock).
std::size_t countIn(const std::vector<nlohmann::json>& events, const char* kind) {
  return static_cast<std::size_t>(std::count_if(events.begin(), events.end(),
                                                [&](const auto& e) { return e["event"] == kind; }));
}

// A signal as the PLC sees it once it has carried out every command sent before this one (the
// peer runs its commands in order); null when it does not answer within 5 s.
nlohmann::json reportOf(PymodbusPlc& plc, const std::string& signal) {
  const std::size_t before = plc.events("report").size();
  plc.command("report " + signal);
  if (!plc.waitFor([&](const auto& all) { return countIn(all, "report") > before; }, 5s))
    return nullptr;
  return plc.events("report").back()["value"];
}

// Waits until the PLC's trigger is low and the link has read it low: only then is the next
// "trigger" a rising edge for the link. Neither a fixed sleep nor the peer's own state is
// enough on a loaded machine: the peer may take the clearing and the next raise in one scan,
// and the link may not poll in between. The link writes the heartbeat at the start of each
// step and reads the trigger after it, so the second heartbeat written after the trigger was
// seen low ends a step that read it low.
bool waitForTriggerLowSeenByLink(PymodbusPlc& plc) {
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (reportOf(plc, "trigger") != false) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(5ms);
  }
  const auto beat = reportOf(plc, "heartbeat");
  if (!beat.is_number()) return false;
  while (true) {
    const auto now = reportOf(plc, "heartbeat");
    if (now.is_number() && now.get<int>() >= beat.get<int>() + 2) return true;
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(5ms);
  }
}

void triggeredRoundTrip(const RegisterMap& map) {
  const int port = test::freeTcpPort();
  PymodbusPlc plc(test::writePeerConfig(map, false), port);
  plc.start();
  plc.command("set_register " +  // recipe select
              std::to_string(map.wireAddress(map.control.recipeSelect->address)) + " 7");
  PlcLink link(map, fastSettings(port));
  link.setActiveRecipe(7);
  link.start();
  ASSERT_TRUE(waitUntil([&] { return link.stats().connected; }, 5s));

  for (int round = 0; round < 2; ++round) {
    plc.command("trigger");
    const auto trigger = link.waitTrigger(5s);
    ASSERT_TRUE(trigger) << "no trigger seen, round " << round << " (accepted "
                         << link.stats().triggers << ", missed " << link.stats().missedTriggers
                         << ", peer events " << plc.events("result").size() << ")";
    EXPECT_EQ(trigger->sequence, static_cast<std::uint64_t>(round + 1));
    EXPECT_EQ(trigger->recipe, 7);
    const InspectionResult sent = sampleResult(map, round, "part-" + std::to_string(round));
    ASSERT_TRUE(link.publish(sent));
    ASSERT_TRUE(plc.waitFor(
        [&](const auto& all) { return countIn(all, "result") == std::size_t(round + 1); }, 5s));
    const auto got = plc.events("result").back();
    expectDelivered(map, sent, got, round + 1);
    EXPECT_EQ(got["toggle"], round == 0);  // flips with every result
    ASSERT_TRUE(
        waitUntil([&] { return link.stats().acknowledged == std::uint64_t(round + 1); }, 5s));
  }
  const auto stats = link.stats();
  EXPECT_EQ(stats.triggers, 2u);
  EXPECT_EQ(stats.written, 2u);
  EXPECT_EQ(stats.dropped, 0u);
  EXPECT_EQ(stats.missedTriggers, 0u);
  EXPECT_EQ(link.requestedRecipe(), 7);
  const auto timings = link.takeTimings();
  ASSERT_EQ(timings.size(), 2u);
  for (const auto& t : timings) {
    ASSERT_TRUE(t.triggerToBusy);
    ASSERT_TRUE(t.resultValidToAck);
    EXPECT_GT(t.handshakeLatency().count(), 0);
    EXPECT_LT(t.handshakeLatency(), 1s);
  }
  EXPECT_EQ(timings[1].inspectionCounter, 2);
}

TEST(PlcLinkWithPymodbus, TriggeredHandshakeDeliversEveryTypeAndWordOrder) {
  triggeredRoundTrip(fullMap(0));
}

// The example station map keeps its status flags in adjacent coils: they go out in one request.
TEST(PlcLinkWithPymodbus, ExampleStationMapWithAdjacentStatusCoils) {
  RegisterMap map =
      loadRegisterMap(std::string(FACET_SOURCE_DIR) + "/tests/plc/data/station_register_map.yaml");
  map.control.enable.reset();  // the pymodbus PLC does not enable; tested separately
  triggeredRoundTrip(map);
}

TEST(PlcLinkWithPymodbus, OneBasedMapReachesTheSameWireAddresses) {
  triggeredRoundTrip(fullMap(1));
}

TEST(PlcLinkWithPymodbus, TriggerWhileBusyRaisesMissedTrigger) {
  const RegisterMap map = fullMap();
  const int port = test::freeTcpPort();
  PymodbusPlc plc(test::writePeerConfig(map, false), port);
  plc.start();
  PlcLink link(map, fastSettings(port));
  link.start();
  plc.command("trigger");
  ASSERT_TRUE(link.waitTrigger(5s));
  // The peer clears the first trigger when busy rises; the second pulse must be a new edge.
  ASSERT_TRUE(waitForTriggerLowSeenByLink(plc)) << "the first trigger was never cleared";
  plc.command("trigger");  // still busy: no result published yet
  ASSERT_TRUE(
      plc.waitFor([&](const auto& all) { return countIn(all, "missed_trigger") == 1; }, 5s));
  EXPECT_EQ(link.stats().missedTriggers, 1u);
  EXPECT_FALSE(link.waitTrigger(0ms)) << "a missed trigger must not start an inspection";

  ASSERT_TRUE(link.publish(sampleResult(map, 0, "late")));
  ASSERT_TRUE(plc.waitFor([&](const auto& all) { return countIn(all, "result") == 1; }, 5s));
  ASSERT_TRUE(waitUntil([&] { return link.stats().acknowledged == 1; }, 5s));
  // The peer drops a pulse raised while busy when the result arrives, at the latest after 0.5 s.
  ASSERT_TRUE(waitForTriggerLowSeenByLink(plc)) << "the missed trigger was never cleared";
  plc.command("trigger");  // no longer busy: accepted
  ASSERT_TRUE(link.waitTrigger(5s));
  EXPECT_EQ(link.stats().missedTriggers, 1u);
}

// Results published at a steady pace while the PLC is killed and restarted: every result arrives,
// in order, none dropped; a repeat of the result in flight at the kill is allowed (same counter).
TEST(PlcLinkWithPymodbus, NoResultLostWhenThePlcRestarts) {
  const RegisterMap map = fullMap();
  const int port = test::freeTcpPort();
  const std::string config = test::writePeerConfig(map, false);
  auto plc = std::make_unique<PymodbusPlc>(config, port);
  plc->start();
  PlcLink link(map, fastSettings(port));
  link.start();

  constexpr int kResults = 40;
  std::vector<InspectionResult> sent;
  for (int i = 0; i < kResults; ++i) sent.push_back(sampleResult(map, i, fmt::format("p{}", i)));
  std::thread producer([&] {
    for (const auto& r : sent) {
      EXPECT_TRUE(link.publish(r));
      std::this_thread::sleep_for(10ms);
    }
  });
  ASSERT_TRUE(plc->waitFor([&](const auto& all) { return countIn(all, "result") >= 10; }, 10s));
  plc->kill();
  // Read after the kill: a result the PLC reported (and acknowledged) just before it died counts.
  std::vector<nlohmann::json> received = plc->events("result");
  std::this_thread::sleep_for(150ms);  // results keep coming while the PLC is down
  plc = std::make_unique<PymodbusPlc>(config, port);
  plc->start();
  producer.join();
  const bool all = plc->waitFor(
      [&](const auto& all) {
        for (const auto& e : all)
          if (e["event"] == "result" && e["counter"] == kResults) return true;
        return false;
      },
      20s);
  for (const auto& e : plc->events("result")) received.push_back(e);
  ASSERT_TRUE(all) << "last result never arrived";

  std::vector<int> counters;
  for (const auto& e : received) {
    const int c = e["counter"];
    if (!counters.empty() && counters.back() == c) continue;  // the repeat after a reconnect
    counters.push_back(c);
    expectDelivered(map, sent.at(c - 1), e, c);
  }
  std::vector<int> expected(kResults);
  for (int i = 0; i < kResults; ++i) expected[i] = i + 1;
  EXPECT_EQ(counters, expected);
  const auto stats = link.stats();
  EXPECT_EQ(stats.dropped, 0u);
  EXPECT_GE(stats.connectionLosses, 1u);
  EXPECT_GE(stats.connects, 2u);
  EXPECT_TRUE(waitUntil([&] { return link.stats().queueDepth == 0; }, 5s));
}

// The PLC is down at start; the queue holds 3; later results are dropped, counted and logged per
// part; the PLC sees the kept ones in order and the gap in the counter after them.
TEST(PlcLinkWithPymodbus, UnreachableAtStartQueuesThenDropsWithACount) {
  const RegisterMap map = fullMap();
  const int port = test::freeTcpPort();
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("plc-test", sink));

  PlcSettings settings = fastSettings(port);
  settings.queueCapacity = 3;
  PlcLink link(map, settings);
  link.start();
  std::vector<InspectionResult> sent;
  for (int i = 0; i < 5; ++i) {
    sent.push_back(sampleResult(map, i, "part-" + std::to_string(i)));
    EXPECT_EQ(link.publish(sent.back()), i < 3) << i;
  }
  EXPECT_EQ(link.stats().dropped, 2u);
  EXPECT_EQ(link.stats().queueDepth, 3u);
  EXPECT_FALSE(link.stats().connected);
  std::this_thread::sleep_for(100ms);  // a few failed connects with backoff

  PymodbusPlc plc(test::writePeerConfig(map, false), port);
  plc.start();
  ASSERT_TRUE(plc.waitFor([&](const auto& all) { return countIn(all, "result") == 3; }, 10s))
      << "written " << link.stats().written << " connects " << link.stats().connects << " errors "
      << link.stats().modbusErrors << " results " << plc.events("result").size();
  ASSERT_TRUE(waitUntil([&] { return link.stats().acknowledged == 3; }, 5s));
  const auto results = plc.events("result");
  for (int i = 0; i < 3; ++i) expectDelivered(map, sent[i], results[i], i + 1);

  sent.push_back(sampleResult(map, 6, "after"));
  ASSERT_TRUE(link.publish(sent.back()));
  ASSERT_TRUE(plc.waitFor([&](const auto& all) { return countIn(all, "result") == 4; }, 5s));
  EXPECT_EQ(plc.events("result").back()["counter"], 6) << "dropped parts leave a counter gap";
  link.stop();
  spdlog::set_default_logger(previous);
  EXPECT_THAT(log.str(), HasSubstr("result of part 'part-3' (inspection counter 4) dropped"));
  EXPECT_THAT(log.str(), HasSubstr("result of part 'part-4' (inspection counter 5) dropped"));
  EXPECT_THAT(log.str(), HasSubstr("cannot connect to 127.0.0.1:" + std::to_string(port)));
}

// Nobody listens on the port: the first warning says what is wrong; later failures are
// logged ever more rarely (attempts 1, 2, 4, 8, ...) while the link keeps retrying
// at its pace (it logged every attempt, twice a second, forever).
TEST(PlcLink, AnUnreachablePlcIsSaidOnceThenTheLogBacksOff) {
  const RegisterMap map = fullMap();
  const int port = test::freeTcpPort();
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("plc-test", sink));
  PlcSettings settings = fastSettings(port);
  settings.reconnectInitial = 5ms;
  settings.reconnectMax = 10ms;
  {
    PlcLink link(map, settings);
    link.start();
    std::this_thread::sleep_for(1500ms);  // about 100 attempts
    link.stop();
  }
  spdlog::set_default_logger(previous);
  const std::string text = log.str();
  std::size_t warnings = 0;
  for (auto at = text.find("cannot connect"); at != std::string::npos;
       at = text.find("cannot connect", at + 1))
    ++warnings;
  EXPECT_GE(warnings, 3u) << text;
  EXPECT_LE(warnings, 9u) << "logged at attempts 1, 2, 4, ..., 128 at most:\n" << text;
  EXPECT_EQ(text.find("cannot connect to 127.0.0.1:" + std::to_string(port)),
            text.find("cannot connect"));
  const std::size_t firstAt = text.find("cannot connect");
  ASSERT_NE(firstAt, std::string::npos) << text;
  const std::string first = text.substr(firstAt, text.find('\n', firstAt) - firstAt);
  EXPECT_THAT(first, HasSubstr("attempt 1"));
}

TEST(PlcLinkWithPymodbus, FreeRunWritesEveryResultWithTheNextCounter) {
  RegisterMap map = fullMap();
  map.control = {};
  const int port = test::freeTcpPort();
  // The peer reports each write of the counter as it lands: a scan for a changed counter would
  // miss one when a link starved of CPU writes two results within one scan of the peer.
  PymodbusPlc plc(test::writePeerConfig(map, true, 512, 128, {{"report_writes", true}}), port);
  plc.start();
  PlcSettings settings = fastSettings(port);
  settings.mode = HandshakeMode::FreeRun;
  PlcLink link(map, settings);
  link.start();
  std::vector<InspectionResult> sent;
  for (int i = 0; i < 6; ++i) {
    sent.push_back(sampleResult(map, i, "free-" + std::to_string(i)));
    ASSERT_TRUE(link.publish(sent.back()));
  }
  ASSERT_TRUE(plc.waitFor([&](const auto& all) { return countIn(all, "result") == 6; }, 10s));
  const auto results = plc.events("result");
  for (int i = 0; i < 6; ++i) expectDelivered(map, sent[i], results[i], i + 1);
  // The peer saw the last counter as it landed; the link counts the result once its flags
  // after the counter are written too.
  EXPECT_TRUE(waitUntil([&] { return link.stats().written == 6u; }, 5s))
      << "written " << link.stats().written;
  EXPECT_EQ(link.stats().queueDepth, 0u);
}

// A stopping daemon flushes: every queued result reaches a connected PLC (each counter write
// seen by the peer as it lands). With the PLC gone, flush() does not wait for it, and stop()
// counts what is left as abandoned and logs each part once (stop() runs twice: by hand and in
// the destructor).
TEST(PlcLinkWithPymodbus, FlushDeliversTheQueueAndStopCountsWhatIsLeft) {
  RegisterMap map = fullMap();
  map.control = {};
  const int port = test::freeTcpPort();
  PymodbusPlc plc(test::writePeerConfig(map, true, 512, 128, {{"report_writes", true}}), port);
  plc.start();
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("plc-test", sink));
  PlcSettings settings = fastSettings(port);
  settings.mode = HandshakeMode::FreeRun;
  {
    PlcLink link(map, settings);
    link.start();
    ASSERT_TRUE(waitUntil([&] { return link.stats().connected; }, 5s));
    constexpr int kBurst = 20;
    for (int i = 0; i < kBurst; ++i)
      ASSERT_TRUE(link.publish(sampleResult(map, i, "burst-" + std::to_string(i))));
    EXPECT_TRUE(link.flush(10s));
    EXPECT_EQ(link.stats().queueDepth, 0u);
    EXPECT_EQ(link.stats().written, std::uint64_t(kBurst));
    // The peer printed each result before answering its write; the pipe may still hold them.
    EXPECT_TRUE(plc.waitFor([&](const auto& all) { return countIn(all, "result") >= kBurst; }, 5s));
    std::vector<int> counters;
    for (const auto& e : plc.events("result")) counters.push_back(e["counter"].get<int>());
    std::vector<int> expected(kBurst);
    for (int i = 0; i < kBurst; ++i) expected[i] = i + 1;
    EXPECT_EQ(counters, expected) << "the PLC saw every counter once, in order";

    plc.kill();
    ASSERT_TRUE(waitUntil([&] { return !link.stats().connected; }, 5s));
    ASSERT_TRUE(link.publish(sampleResult(map, 0, "late-a")));
    ASSERT_TRUE(link.publish(sampleResult(map, 1, "late-b")));
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_FALSE(link.flush(5s));
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s) << "flush waited for a PLC that is gone";
    link.stop();
    EXPECT_EQ(link.stats().abandoned, 2u);
    EXPECT_EQ(link.stats().queueDepth, 0u);
  }
  spdlog::set_default_logger(previous);
  const std::string text = log.str();
  for (const std::string part : {"late-a", "late-b"}) {
    const std::string line = "result of part '" + part + "'";
    const auto first = text.find(line);
    EXPECT_NE(first, std::string::npos) << part << " not logged";
    EXPECT_EQ(text.find(line, first + 1), std::string::npos) << part << " logged twice";
  }
  EXPECT_THAT(text, HasSubstr("(inspection counter 22) not delivered: link stopped"));
}

// A result register beyond the PLC's table: the PLC answers "illegal data address"; the log
// names the register and the entry, and the handshake still completes.
TEST(PlcLinkWithPymodbus, ModbusExceptionIsLoggedWithTheRegister) {
  RegisterMap map = fullMap();
  map.results.push_back({"far", 600, ValueType::Int16, 1.0, WordOrder::ABCD, ""});
  const int port = test::freeTcpPort();
  PymodbusPlc plc(test::writePeerConfig(fullMap(), false, /*registers=*/512), port);
  plc.start();
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("plc-test", sink));
  {
    PlcLink link(map, fastSettings(port));
    link.start();
    InspectionResult r = sampleResult(map, 0, "far-part");
    r.values["far"] = 5;
    ASSERT_TRUE(link.publish(r));
    ASSERT_TRUE(plc.waitFor([&](const auto& all) { return countIn(all, "result") == 1; }, 5s));
    ASSERT_TRUE(waitUntil([&] { return link.stats().acknowledged == 1; }, 5s));
    EXPECT_GE(link.stats().modbusErrors, 1u);
  }
  spdlog::set_default_logger(previous);
  EXPECT_THAT(log.str(), HasSubstr("writing holding register 600 for result.far"));
  EXPECT_THAT(log.str(), HasSubstr("Illegal data address"));
}

}  // namespace
}  // namespace facet::plc

namespace facet::plc {
namespace {

// Server role: the daemon serves the registers and a pymodbus client (the PLC) polls them.
TEST(PlcLinkWithPymodbus, ServerRoleLetsThePlcPollTheDaemon) {
  const RegisterMap map = fullMap();
  PlcSettings settings = fastSettings(0);
  settings.role = LinkRole::Server;
  PlcLink link(map, settings);
  link.start();
  ASSERT_GT(link.serverPort(), 0);
  PymodbusPlc plc(test::writePeerConfig(map, false), link.serverPort(), /*clientMode=*/true);
  plc.start();
  for (int round = 0; round < 2; ++round) {
    plc.command("trigger");
    const auto trigger = link.waitTrigger(5s);
    ASSERT_TRUE(trigger) << "round " << round;
    const InspectionResult sent = sampleResult(map, round, "served-" + std::to_string(round));
    ASSERT_TRUE(link.publish(sent));
    ASSERT_TRUE(plc.waitFor(
        [&](const auto& all) { return countIn(all, "result") == std::size_t(round + 1); }, 5s));
    expectDelivered(map, sent, plc.events("result").back(), round + 1);
    ASSERT_TRUE(
        waitUntil([&] { return link.stats().acknowledged == std::uint64_t(round + 1); }, 5s));
  }
}

}  // namespace
}  // namespace facet::plc

namespace facet::plc {
namespace {

// control.enable = 0: the line is not running; triggers are ignored (neither accepted nor missed).
TEST(PlcLinkWithPymodbus, TriggersAreIgnoredWhileNotEnabled) {
  RegisterMap map = fullMap();
  map.control.enable = reg(6);
  const int port = test::freeTcpPort();
  PymodbusPlc plc(test::writePeerConfig(map, false), port);
  plc.start();
  PlcLink link(map, fastSettings(port));
  link.start();
  ASSERT_TRUE(waitUntil([&] { return link.stats().connected; }, 5s));
  plc.command("trigger");
  EXPECT_FALSE(link.waitTrigger(300ms));
  EXPECT_EQ(link.stats().triggers, 0u);
  EXPECT_EQ(link.stats().missedTriggers, 0u);
  plc.command("untrigger");  // the unanswered trigger goes low before enable rises
  ASSERT_TRUE(waitForTriggerLowSeenByLink(plc));
  plc.command("set_register 6 1");
  plc.command("trigger");
  EXPECT_TRUE(link.waitTrigger(5s));
}

}  // namespace
}  // namespace facet::plc

namespace facet::plc {
namespace {

// What the daemon owns besides results: ready, active recipe, a heartbeat that keeps counting.
TEST(PlcLinkWithPymodbus, ReadyActiveRecipeAndHeartbeatReachThePlc) {
  const RegisterMap map = fullMap();
  const int port = test::freeTcpPort();
  PymodbusPlc plc(test::writePeerConfig(map, false), port);
  plc.start();
  PlcLink link(map, fastSettings(port));  // heartbeat every 20 ms
  link.setActiveRecipe(12);
  link.start();
  ASSERT_TRUE(waitUntil([&] { return link.stats().connected; }, 5s));
  // The link writes them after it connected, on its own thread: the PLC sees them within 5 s
  // (a few ms on an idle machine).
  auto reportBecomes = [&](const std::string& signal, const nlohmann::json& value) {
    return waitUntil([&] { return reportOf(plc, signal) == value; }, 5s);
  };
  EXPECT_TRUE(reportBecomes("ready", true));
  EXPECT_TRUE(reportBecomes("active_recipe", 12));
  const int beat = reportOf(plc, "heartbeat");
  EXPECT_TRUE(waitUntil(
      [&] {
        const auto now = reportOf(plc, "heartbeat");
        return now.is_number() && now.get<int>() >= beat + 3;
      },
      5s))
      << "the heartbeat stopped at " << reportOf(plc, "heartbeat");
  link.setReady(false);
  link.setActiveRecipe(4);
  EXPECT_TRUE(reportBecomes("ready", false));
  EXPECT_TRUE(reportBecomes("active_recipe", 4));
}

}  // namespace
}  // namespace facet::plc
