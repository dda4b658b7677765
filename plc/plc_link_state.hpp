#pragma once
// The PLC link's inner state, shared by its three parts: the signal access (plc_link_signals.cpp),
// the I/O thread that runs the handshake (plc_link_handshake.cpp) and the daemon's side
// (plc_link.cpp). Private to plc/: nothing outside includes it.

#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "plc/plc_link.hpp"
#include "plc/register_bus.hpp"
#include "plc/register_server.hpp"

namespace facet::plc {

inline constexpr std::size_t kTriggerQueueCapacity = 16;
inline constexpr std::size_t kTimingHistory = 1024;
inline constexpr int kMaxRegistersPerWrite = 123;  // Modbus limit of function code 16

// Thrown when the peer answered "device busy": the step is tried again on the next poll.
struct TryAgain {};

struct Pending {
  InspectionResult result;
  std::uint16_t counter = 0;
  Clock::time_point publishedAt;
};

struct TriggerTimes {
  Clock::time_point seen;
  Clock::time_point busyWritten;
};

// One holding register to write, with the entry it belongs to (for messages).
struct RegisterWrite {
  int wire;
  std::uint16_t value;
  std::string name;
};

struct PlcLink::State {
  RegisterMap map;
  PlcSettings settings;
  std::unique_ptr<RegisterServer> server;  // server role only
  std::unique_ptr<RegisterBus> bus;

  // Shared with the daemon's threads, under `mutex`.
  mutable std::mutex mutex;
  std::condition_variable wake;            // the I/O thread's sleep
  std::condition_variable triggerArrived;  // waitTrigger()
  std::condition_variable queueChanged;    // flush(): a result left the queue, or the link fell
  std::deque<Pending> queue;
  std::deque<TriggerEvent> triggers;
  std::deque<HandshakeTiming> timings;
  PlcLinkStats stats;
  bool stopping = false;
  bool wakeRequested = false;
  bool ready = true;
  int activeRecipe = -1;
  bool daemonStatusDirty = true;
  bool dropClearsBusy = false;
  std::uint16_t nextCounter = 1;
  int requestedRecipe = -1;
  std::thread thread;

  // I/O thread only.
  bool connected = false;
  bool lastTrigger = false;
  bool lastAck = false;
  bool busy = false;
  bool missedLatched = false;
  bool toggle = false;
  bool headWritten = false;
  Clock::time_point headValidAt;
  std::optional<TriggerTimes> headTrigger;  // timing of the trigger the head result answers
  std::optional<TriggerTimes> openTrigger;  // accepted, not yet answered by a written result
  std::uint64_t triggerSequence = 0;
  std::uint16_t heartbeat = 0;
  Clock::time_point nextHeartbeat;
  std::chrono::milliseconds backoff{0};
  std::uint64_t failedConnects = 0;  // since the last connect
  std::map<std::string, std::uint64_t> exceptionCounts;

  // --- the I/O thread -------------------------------------------------------------------------
  void run();
  bool sleepFor(std::chrono::milliseconds duration);  // false when stopping
  void connect();
  void onConnected();
  void step();
  void pollTrigger(bool triggerLevel);
  void deliverHead();
  void writeResult(const Pending& pending, bool clearBusy);
  void writeResultFlags(bool pass, bool error, bool clearBusy, bool withVerdict);
  void writeDaemonStatus();
  void beat();

  // --- signal access (wraps the bus with names and exception handling) ------------------------
  // Runs one Modbus request; counts and logs its exception, throws TryAgain on "device busy".
  void request(const std::string& name, const std::string& what, const std::function<void()>& f);
  bool readFlag(const char* name, const Location& at);
  int readNumber(const char* name, const Location& at);
  void writeFlag(const char* name, const std::optional<Location>& at, bool value);
  void writeNumber(const char* name, const std::optional<Location>& at, int value);
  void writeRegisterRuns(std::vector<RegisterWrite> writes);
};

}  // namespace facet::plc
