#pragma once
// PlcLink: the daemon's side of the trigger/result handshake with the line's PLC.
//
// The inspection loop never waits on the network: publish() only queues, and triggers are read
// from a queue filled by the link's own I/O thread. That thread owns the Modbus connection,
// reconnects with exponential backoff when the PLC is unreachable, and delivers queued results
// in order once it is back.
//
// Triggered handshake (RegisterMap names; the daemon is the Modbus client):
//   PLC trigger 0->1          -> busy = 1, a TriggerEvent is queued for the daemon
//   daemon publish(result)    -> all result registers, error code, inspection counter are
//                                written, then pass, error, completed toggle (flipped),
//                                result valid = 1 and busy = 0 (one request when these are
//                                adjacent coils, else in this order)
//   PLC result ack 0->1       -> result valid = 0
//   PLC result ack 1->0       -> the next queued result may follow (four-phase handshake)
//   trigger 0->1 while busy   -> missed trigger = 1 (latched until the next accepted trigger)
// Free-run handshake: each result is written with the next inspection counter and the toggle
// flipped (the verdict before the counter, the counter last but for toggle and result valid);
// no trigger, no acknowledge. Results wait for the acknowledge without a time limit: a PLC that
// never acknowledges fills the queue, and the overflow is reported part by part.
// The PLC must hold the trigger (and the acknowledge) low and high for a few poll periods.
//
// A result leaves the queue only once acknowledged (triggered) or written (free run); after a
// reconnect the head result is written again with the same inspection counter, so a PLC that
// saw it already recognises the repeat. Every published result takes the next inspection
// counter, dropped ones too, so a PLC sees a gap where a part was dropped.

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "plc/plc_settings.hpp"
#include "plc/register_map.hpp"

namespace facet::plc {

using Clock = std::chrono::steady_clock;

// One inspection's verdict and measured values, as the daemon hands it to the link.
struct InspectionResult {
  std::string partId;  // names the part in logs (e.g. "recipe-a/000123")
  bool pass = false;
  std::map<std::string, double> values;  // by ResultOutput::name; a mapped output that is
                                         // missing is written as NaN/0 and logged
  int errorCode = 0;                     // 0 = inspection ran; sets status.error when non-zero
  std::uint64_t triggerSequence = 0;     // TriggerEvent::sequence it answers; 0 = none
  // Mapped outputs missing from `values` are left unwritten instead of written as NaN/0 and
  // logged: a station with several recipes maps every recipe's outputs, a part has only its own.
  bool onlyGivenValues = false;
};

// A trigger the PLC raised and the link accepted (busy is already written when it is queued).
struct TriggerEvent {
  std::uint64_t sequence = 0;  // 1, 2, 3, ... per link
  int recipe = -1;             // control.recipeSelect at the trigger; -1 when not mapped
  Clock::time_point seenAt;    // when the rising edge was read
};

// Durations of one handshake's steps.
struct HandshakeTiming {
  std::uint16_t inspectionCounter = 0;
  std::optional<std::chrono::nanoseconds> triggerToBusy;  // edge read -> busy written (triggered)
  std::chrono::nanoseconds publishToResultValid{};  // publish() -> result valid written (queueing
                                                    // and writing of every result register)
  std::optional<std::chrono::nanoseconds> resultValidToAck;  // PLC's reaction (triggered)
  std::optional<std::chrono::nanoseconds> ackToClear;        // ack read -> result valid cleared
  // The link's own latency, inspection excluded: trigger seen -> busy written plus
  // result published -> result valid written.
  std::chrono::nanoseconds handshakeLatency() const {
    return triggerToBusy.value_or(std::chrono::nanoseconds{0}) + publishToResultValid;
  }
};

struct PlcLinkStats {
  bool connected = false;
  std::uint64_t published = 0;       // publish() calls
  std::uint64_t written = 0;         // results whose result valid (or counter) was written
  std::uint64_t acknowledged = 0;    // results the PLC acknowledged (triggered)
  std::uint64_t dropped = 0;         // results dropped because the queue was full
  std::uint64_t abandoned = 0;       // results still waiting when the link stopped (logged)
  std::uint64_t triggers = 0;        // triggers accepted
  std::uint64_t missedTriggers = 0;  // triggers while busy
  std::uint64_t connects = 0;        // successful connects (first one included)
  std::uint64_t connectionLosses = 0;
  std::uint64_t modbusErrors = 0;  // failed requests, exceptions included
  std::size_t queueDepth = 0;      // results waiting (including one written, not yet acked)
};

class PlcLink {
 public:
  // Throws std::invalid_argument listing every RegisterMap::validate() issue, or when the
  // handshake mode needs a signal the map lacks (triggered: control.trigger, control.resultAck,
  // status.resultValid).
  PlcLink(RegisterMap map, PlcSettings settings);
  ~PlcLink();  // stops the I/O thread, then closes the connection
  PlcLink(const PlcLink&) = delete;
  PlcLink& operator=(const PlcLink&) = delete;

  // Starts the I/O thread; returns at once (the PLC may be unreachable).
  void start();
  // Stops the I/O thread. Results still queued are counted as abandoned and logged as
  // undelivered, part by part.
  void stop();
  // Waits until every queued result has left the queue (free run: written; triggered:
  // acknowledged), the link is down, or `timeout` has passed; returns whether the queue is
  // empty. For a clean shutdown: the last parts reach a PLC that is there.
  bool flush(std::chrono::milliseconds timeout);

  // Queues a result for the PLC. Never blocks on the network. Returns false when the queue was
  // full and the result was dropped (counted and logged as an error naming the part).
  bool publish(InspectionResult result);

  // The next accepted trigger, waiting at most `timeout` (0: just look).
  std::optional<TriggerEvent> waitTrigger(std::chrono::milliseconds timeout);

  // Status the daemon owns; written by the I/O thread on change and after every reconnect.
  void setReady(bool ready);
  void setActiveRecipe(int recipe);

  // control.recipeSelect as last read; -1 when not mapped or never read.
  int requestedRecipe() const;

  PlcLinkStats stats() const;
  // Timings of the handshakes completed since the last call (at most the last 1024).
  std::vector<HandshakeTiming> takeTimings();

  // Server role: the port the daemon serves on (useful with port 0); -1 in the client role.
  int serverPort() const;

  const RegisterMap& registerMap() const;
  const PlcSettings& settings() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace facet::plc
