#include "tests/daemon/plc_line.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <thread>

#include "tests/daemon/line_run.hpp"

namespace facet::daemon_test {

using namespace std::chrono_literals;

namespace {

// Events of one kind counted, for plc.waitFor.
auto atLeast(const std::string& kind, std::size_t n) {
  return [kind, n](const std::vector<nlohmann::json>& events) {
    std::size_t count = 0;
    for (const auto& e : events) count += e.value("event", "") == kind;
    return count >= n;
  };
}

}  // namespace

PlcLine::~PlcLine() {
  std::error_code ignored;
  if (!peerConfig_.empty()) std::filesystem::remove(peerConfig_, ignored);
}

void PlcLine::start(const std::string& cameraSection, int recipe, const std::string& logLevel) {
  const auto station = writeStationFile(dir_.path(), cameraSection, plcPort_);
  peerConfig_ = writePeerConfig(station);
  plc_ = std::make_unique<plc::test::PymodbusPlc>(peerConfig_, plcPort_);
  plc_->start();
  plc_->command("set_register 0 " + std::to_string(recipe));
  facetd_ = std::make_unique<ChildProcess>(
      std::vector<std::string>{FACETD_PATH, "--config", station, "--http-port-file",
                               dir_ / "http.port", "--log-level", logLevel},
      std::map<std::string, std::string>{}, dir_ / "facetd.log");
}

std::size_t PlcLine::resultCount() const {
  return plc_->events("result").size();
}

bool PlcLine::part(std::size_t n, std::chrono::milliseconds timeout) {
  plc_->command("trigger");
  return plc_->waitFor(atLeast("result", n), timeout);
}

void PlcLine::runParts(int parts, std::chrono::milliseconds perPart) {
  std::size_t n = resultCount();
  if (n == 0 && parts > 0) {
    // As a PLC program does: no trigger before facetd says it is ready (its start under ASan
    // takes seconds). A trigger raised earlier and held is not lost (the first poll sees a
    // rising edge), but raising it again and again would keep it high through the first part.
    bool ready = false;
    const auto until = std::chrono::steady_clock::now() + 120s;
    for (std::size_t asked = 1; !ready && std::chrono::steady_clock::now() < until; ++asked) {
      plc_->command("report ready");
      ASSERT_TRUE(plc_->waitFor(atLeast("report", asked), 5s)) << "the PLC does not answer";
      ready = plc_->events("report").back().value("value", false);
      if (!ready) std::this_thread::sleep_for(100ms);
    }
    ASSERT_TRUE(ready) << "facetd never said it was ready\n" << facetd_->outputTail();
  }
  for (int i = 0; i < parts; ++i)
    ASSERT_TRUE(part(++n, perPart))
        << "no result for trigger " << n << " within " << perPart.count() << " ms\n"
        << facetd_->outputTail();
}

void PlcLine::stop() {
  facetd_->signal(SIGTERM);
  const auto code = facetd_->wait(20s);
  ASSERT_TRUE(code.has_value()) << "facetd did not exit within 20 s of SIGTERM\n"
                                << facetd_->outputTail();
  EXPECT_EQ(*code, 0) << facetd_->outputTail();
}

}  // namespace facet::daemon_test
