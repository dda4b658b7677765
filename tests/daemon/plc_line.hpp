#pragma once
// PlcLine: facetd in triggered mode between a camera (the station file's camera section) and the
// pymodbus PLC (tests/plc/pymodbus_plc.py), which selects the recipe, raises one trigger at a
// time, decodes each result and acknowledges it. The line tests of tests/daemon drive it.

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/daemon/child_process.hpp"
#include "tests/plc/pymodbus_peer.hpp"

namespace facet::daemon_test {

class PlcLine {
 public:
  PlcLine() = default;
  ~PlcLine();
  PlcLine(const PlcLine&) = delete;
  PlcLine& operator=(const PlcLine&) = delete;

  // Writes the station file (results, archive and HTTP port file in dir()), starts the PLC with
  // `recipe` selected, then facetd (stderr to dir()/facetd.log). Throws when the PLC does not
  // start.
  void start(const std::string& cameraSection, int recipe, const std::string& logLevel = "warn");

  // Raises one trigger and waits until the PLC has seen `n` results in all.
  bool part(std::size_t n, std::chrono::milliseconds timeout);
  // `parts` parts one after the other, each trigger raised once the previous result was
  // acknowledged. The first trigger waits until facetd is ready: raised before facetd connects,
  // it is a rising edge to facetd's first poll (which sees the level), so it is raised once and
  // then only again after the PLC has dropped it. Fails the test (ASSERT) with facetd's output.
  void runParts(int parts, std::chrono::milliseconds perPart);

  // SIGTERM: facetd finishes, flushes and exits 0.
  void stop();

  std::size_t resultCount() const;
  std::vector<nlohmann::json> results() const { return plc_->events("result"); }
  plc::test::PymodbusPlc& plc() { return *plc_; }
  ChildProcess& facetd() { return *facetd_; }
  const TempDir& dir() const { return dir_; }
  std::string database() const { return dir_ / "results.db"; }

 private:
  TempDir dir_;
  int plcPort_ = plc::test::freeTcpPort();
  std::string peerConfig_;  // a /tmp file of writePeerConfig()
  std::unique_ptr<plc::test::PymodbusPlc> plc_;
  std::unique_ptr<ChildProcess> facetd_;
};

}  // namespace facet::daemon_test
