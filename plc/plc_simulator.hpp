#pragma once
// PlcSimulator: a stand-in for the line's PLC. It serves a RegisterMap over Modbus TCP (via
// RegisterServer), raises triggers at a rate, reads and acknowledges every result the daemon
// writes, and reports each one. `facet plc-sim` runs it; the daemon demo talks to it.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "plc/plc_settings.hpp"
#include "plc/register_map.hpp"

namespace facet::plc {

struct PlcSimulatorOptions {
  std::string host = "127.0.0.1";
  int port = 0;                                   // 0: pick a free port (see PlcSimulator::port())
  double triggerRate = 0.0;                       // triggers per second; 0: only raiseTrigger()
  HandshakeMode mode = HandshakeMode::Triggered;  // FreeRun: watch the counter, never ack
  std::chrono::milliseconds ackDelay{0};          // wait after result valid before acknowledging
  std::chrono::milliseconds triggerPulse{1000};   // trigger is cleared when busy (or a result)
                                                  // shows, at the latest after this
  std::chrono::milliseconds triggerGap{5};    // the trigger stays low at least this long between
                                              // pulses (a polling daemon must see it low)
  std::chrono::microseconds scanPeriod{500};  // the simulated PLC's scan cycle
};

// A result as the simulator read it from its registers.
struct ReceivedResult {
  int inspectionCounter = -1;  // -1 when not mapped
  bool pass = false;
  int errorCode = 0;
  std::map<std::string, double> values;  // decoded by the map's types and word orders
  std::chrono::steady_clock::time_point receivedAt;
};

struct PlcSimulatorStats {
  std::uint64_t triggersRaised = 0;
  std::uint64_t results = 0;
  std::uint64_t missedTriggersSeen = 0;  // rising edges of status.missedTrigger
};

class PlcSimulator {
 public:
  // Throws std::invalid_argument when the map has issues, std::runtime_error when it cannot bind.
  PlcSimulator(RegisterMap map, PlcSimulatorOptions options);
  ~PlcSimulator();
  PlcSimulator(const PlcSimulator&) = delete;
  PlcSimulator& operator=(const PlcSimulator&) = delete;

  int port() const;

  // Called from the simulator's scan thread once per result it reads.
  void onResult(std::function<void(const ReceivedResult&)> callback);

  // Starts / stops the scan thread (serving starts in the constructor).
  void start();
  void stop();

  // Raises the trigger once (as the rate does).
  void raiseTrigger();

  PlcSimulatorStats stats() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// One line describing a result, as `facet plc-sim` prints it:
// "result #12 PASS error=0 hole.diameter_mm=12.5 offset_x_mm=-0.03".
std::string describe(const ReceivedResult& result);

}  // namespace facet::plc
