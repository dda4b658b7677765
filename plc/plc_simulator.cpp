#include "plc/plc_simulator.hpp"

#include <atomic>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "plc/register_encoding.hpp"
#include "plc/register_server.hpp"

namespace facet::plc {
namespace {

using SteadyClock = std::chrono::steady_clock;

// Local access to the simulator's own tables through the map's locations.
class Tables {
 public:
  Tables(RegisterServer& server, const RegisterMap& map) : server_(server), map_(map) {}

  bool flag(const std::optional<Location>& at) const {
    if (!at) return false;
    const int wire = map_.wireAddress(at->address);
    if (at->table == Table::Coil) return server_.coil(wire);
    const std::uint16_t word = server_.holdingRegister(wire);
    return at->bit >= 0 ? ((word >> at->bit) & 1u) != 0 : word != 0;
  }

  void setFlag(const std::optional<Location>& at, bool value) {
    if (!at) return;
    const int wire = map_.wireAddress(at->address);
    if (at->table == Table::Coil) return server_.setCoil(wire, value);
    if (at->bit < 0) return server_.setHoldingRegister(wire, value ? 1 : 0);
    const auto mask = static_cast<std::uint16_t>(1u << at->bit);
    const std::uint16_t word = server_.holdingRegister(wire);
    server_.setHoldingRegister(wire, value ? static_cast<std::uint16_t>(word | mask)
                                           : static_cast<std::uint16_t>(word & ~mask));
  }

  int number(const std::optional<Location>& at) const {
    return at ? server_.holdingRegister(map_.wireAddress(at->address)) : -1;
  }

  ReceivedResult readResult() const {
    ReceivedResult result;
    result.inspectionCounter = number(map_.status.inspectionCounter);
    result.pass = flag(map_.status.pass);
    result.errorCode = map_.status.errorCode ? number(map_.status.errorCode) : 0;
    for (const auto& output : map_.results) {
      std::uint16_t words[2] = {0, 0};
      server_.holdingRegisters(map_.wireAddress(output.address), registerCount(output.type), words);
      result.values[output.name] = decodeValue(output, words);
    }
    result.receivedAt = SteadyClock::now();
    return result;
  }

 private:
  RegisterServer& server_;
  const RegisterMap& map_;
};

// The largest wire address the map uses in `table`, so the server's tables cover the map.
int tableSize(const RegisterMap& map, Table table) {
  int highest = 0;
  for (const auto& signal : namedSignals(map))
    if (signal.location->table == table)
      highest = std::max(highest, map.wireAddress(signal.location->address));
  if (table == Table::HoldingRegister)
    for (const auto& output : map.results)
      highest = std::max(highest, map.wireAddress(output.address) + registerCount(output.type) - 1);
  // Like a real PLC's data block, the tables are larger than the station's own signals: recipe
  // outputs (which the simulator does not know) land above them.
  constexpr int kMinimumTable = 1024;
  return std::max(highest + 1, kMinimumTable);
}

}  // namespace

struct PlcSimulator::State {
  RegisterMap map;
  PlcSimulatorOptions options;
  std::unique_ptr<RegisterServer> server;
  std::thread thread;
  std::atomic<bool> stopping{false};
  std::atomic<bool> triggerRequested{false};
  mutable std::mutex mutex;  // guards stats and callback
  PlcSimulatorStats stats;
  std::function<void(const ReceivedResult&)> callback;
  // Free run: the counter and toggle when start() was called; a change after that is a result
  // (read before the scan thread runs, so a result written right after start() is not missed).
  int initialCounter = -1;
  bool initialToggle = false;

  void scan();
};

void PlcSimulator::State::scan() {
  Tables tables(*server, map);
  tables.setFlag(map.control.enable, true);  // a running line enables inspections
  const bool triggered = options.mode == HandshakeMode::Triggered;
  const auto ratePeriod = options.triggerRate > 0
                              ? std::chrono::duration_cast<SteadyClock::duration>(
                                    std::chrono::duration<double>(1.0 / options.triggerRate))
                              : SteadyClock::duration::zero();
  auto nextTrigger = SteadyClock::now() + ratePeriod;
  // Plain time points with flags: GCC 12 warns about std::optional<time_point> here.
  bool triggerHigh = false;
  bool raisePending = false;
  SteadyClock::time_point triggerLoweredAt{};
  bool busyAtRaise = false;  // raised while busy: hold the full pulse so the daemon sees it
  SteadyClock::time_point triggerRaisedAt{};
  bool ackPending = false;
  SteadyClock::time_point validSince{};
  bool lastValid = false;
  bool lastMissed = false;
  bool lastToggle = initialToggle;
  int lastCounter = initialCounter;

  while (!stopping) {
    const auto now = SteadyClock::now();
    if (triggered) {
      // Trigger: raised on request or at the rate.
      if (triggerRequested.exchange(false)) raisePending = true;
      if (ratePeriod > SteadyClock::duration::zero() && now >= nextTrigger) {
        // As a line's PLC does, the rate feeds parts only to a daemon that says it is ready:
        // one still starting (or not connected) would only miss them ("trigger while busy").
        if (!map.status.ready || tables.flag(map.status.ready)) raisePending = true;
        nextTrigger += ratePeriod;
      }
      // A polling daemon sees an edge only if the trigger stayed low for a few of its polls.
      if (raisePending && !triggerHigh && now - triggerLoweredAt >= options.triggerGap) {
        raisePending = false;
        tables.setFlag(map.control.trigger, true);
        triggerHigh = true;
        busyAtRaise = tables.flag(map.status.busy);
        triggerRaisedAt = now;
        std::lock_guard lock(mutex);
        ++stats.triggersRaised;
      }
      // Result valid: read everything, acknowledge after the delay, release the ack when the
      // daemon clears result valid.
      const bool valid = tables.flag(map.status.resultValid);
      // The trigger is held until the daemon answers (busy, or a result when the inspection was
      // quicker than a scan), at the latest until the pulse ends.
      if (triggerHigh && ((tables.flag(map.status.busy) && !busyAtRaise) || (valid && !lastValid) ||
                          now - triggerRaisedAt >= options.triggerPulse)) {
        tables.setFlag(map.control.trigger, false);
        triggerHigh = false;
        triggerLoweredAt = now;
      }
      if (valid && !lastValid) {
        const ReceivedResult result = tables.readResult();
        validSince = now;
        ackPending = true;
        std::lock_guard lock(mutex);
        ++stats.results;
        if (callback) callback(result);
      }
      if (valid && ackPending && now - validSince >= options.ackDelay) {
        tables.setFlag(map.control.resultAck, true);
        ackPending = false;
      }
      if (!valid && lastValid) tables.setFlag(map.control.resultAck, false);
      lastValid = valid;
    } else {
      // Free run: a new counter (or a flipped toggle) announces a result.
      const int counter = tables.number(map.status.inspectionCounter);
      const bool toggle = tables.flag(map.status.completedToggle);
      const bool fresh =
          map.status.inspectionCounter ? counter != lastCounter : toggle != lastToggle;
      lastCounter = counter;
      lastToggle = toggle;
      if (fresh) {
        const ReceivedResult result = tables.readResult();
        std::lock_guard lock(mutex);
        ++stats.results;
        if (callback) callback(result);
      }
    }
    const bool missed = tables.flag(map.status.missedTrigger);
    if (missed && !lastMissed) {
      std::lock_guard lock(mutex);
      ++stats.missedTriggersSeen;
    }
    lastMissed = missed;
    std::this_thread::sleep_for(options.scanPeriod);
  }
}

PlcSimulator::PlcSimulator(RegisterMap map, PlcSimulatorOptions options)
    : state_(std::make_unique<State>()) {
  const auto issues = map.validate();
  if (!issues.empty()) {
    std::string message = "invalid PLC register map:";
    for (const auto& issue : issues) message += "\n  " + describe(issue);
    throw std::invalid_argument(message);
  }
  state_->map = std::move(map);
  state_->options = std::move(options);
  RegisterServerOptions serverOptions;
  serverOptions.host = state_->options.host;
  serverOptions.port = state_->options.port;
  serverOptions.coils = tableSize(state_->map, Table::Coil);
  serverOptions.holdingRegisters = tableSize(state_->map, Table::HoldingRegister);
  state_->server = std::make_unique<RegisterServer>(serverOptions);
}

PlcSimulator::~PlcSimulator() {
  stop();
}

int PlcSimulator::port() const {
  return state_->server->port();
}

void PlcSimulator::onResult(std::function<void(const ReceivedResult&)> callback) {
  std::lock_guard lock(state_->mutex);
  state_->callback = std::move(callback);
}

void PlcSimulator::start() {
  if (state_->thread.joinable()) return;
  state_->stopping = false;
  const Tables tables(*state_->server, state_->map);
  state_->initialCounter = tables.number(state_->map.status.inspectionCounter);
  state_->initialToggle = tables.flag(state_->map.status.completedToggle);
  state_->thread = std::thread([s = state_.get()] { s->scan(); });
}

void PlcSimulator::stop() {
  state_->stopping = true;
  if (state_->thread.joinable()) state_->thread.join();
}

void PlcSimulator::raiseTrigger() {
  state_->triggerRequested = true;
}

PlcSimulatorStats PlcSimulator::stats() const {
  std::lock_guard lock(state_->mutex);
  return state_->stats;
}

std::string describe(const ReceivedResult& result) {
  std::ostringstream line;
  line << "result #" << result.inspectionCounter << (result.pass ? " PASS" : " FAIL")
       << " error=" << result.errorCode;
  for (const auto& [name, value] : result.values) line << ' ' << name << '=' << value;
  return line.str();
}

}  // namespace facet::plc
