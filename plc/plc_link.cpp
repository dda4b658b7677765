#include "plc/plc_link.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plc/register_bus.hpp"
#include "plc/register_encoding.hpp"
#include "plc/register_server.hpp"

namespace facet::plc {
namespace {

constexpr std::size_t kTriggerQueueCapacity = 16;
constexpr std::size_t kTimingHistory = 1024;
constexpr int kMaxRegistersPerWrite = 123;  // Modbus limit of function code 16

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

std::string addressText(const Location& at) {
  std::string text =
      (at.table == Table::Coil ? "coil " : "holding register ") + std::to_string(at.address);
  if (at.bit >= 0) text += " bit " + std::to_string(at.bit);
  return text;
}

std::string missingSignals(const RegisterMap& map, HandshakeMode mode) {
  std::string missing;
  auto need = [&](const std::optional<Location>& at, const char* name) {
    if (!at) missing += std::string(missing.empty() ? "" : ", ") + name;
  };
  if (mode == HandshakeMode::Triggered) {
    need(map.control.trigger, "control.trigger");
    need(map.control.resultAck, "control.result_ack");
    need(map.status.resultValid, "status.result_valid");
  } else if (!map.status.inspectionCounter && !map.status.completedToggle) {
    missing = "status.inspection_counter or status.completed_toggle";
  }
  return missing;
}

}  // namespace

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
  template <class F>
  void request(const std::string& name, const std::string& what, F&& f);
  bool readFlag(const char* name, const Location& at);
  int readNumber(const char* name, const Location& at);
  void writeFlag(const char* name, const std::optional<Location>& at, bool value);
  void writeNumber(const char* name, const std::optional<Location>& at, int value);
  void writeRegisterRuns(std::vector<RegisterWrite> writes);
};

// ---------------------------------------------------------------------------------------------
// Signal access

template <class F>
void PlcLink::State::request(const std::string& name, const std::string& what, F&& f) {
  try {
    f();
    if (!exceptionCounts.empty()) exceptionCounts.erase(name);  // logs the next failure again
  } catch (const ModbusException& e) {
    {
      std::lock_guard lock(mutex);
      ++stats.modbusErrors;
    }
    // Log the first exception of a register and then every hundredth, so a PLC that rejects a
    // register every poll does not flood the log.
    const auto n = ++exceptionCounts[name];
    if (n == 1 || n % 100 == 0)
      spdlog::error("PLC {}: Modbus exception {} {} ({}){}", bus->describe(), what, name, e.what(),
                    n > 1 ? fmt::format(", {} times", n) : "");
    if (e.deviceBusy()) throw TryAgain{};
  }
}

bool PlcLink::State::readFlag(const char* name, const Location& at) {
  const int wire = map.wireAddress(at.address);
  bool value = false;
  request(name, "reading " + addressText(at) + " for", [&] {
    if (at.table == Table::Coil) {
      std::uint8_t bit = 0;
      bus->readCoils(wire, 1, &bit);
      value = bit != 0;
    } else {
      std::uint16_t word = 0;
      bus->readRegisters(wire, 1, &word);
      value = at.bit >= 0 ? ((word >> at.bit) & 1u) != 0 : word != 0;
    }
  });
  return value;
}

int PlcLink::State::readNumber(const char* name, const Location& at) {
  std::uint16_t word = 0;
  request(name, "reading " + addressText(at) + " for",
          [&] { bus->readRegisters(map.wireAddress(at.address), 1, &word); });
  return word;
}

void PlcLink::State::writeFlag(const char* name, const std::optional<Location>& at, bool value) {
  if (!at) return;
  const int wire = map.wireAddress(at->address);
  request(name, "writing " + addressText(*at) + " for", [&] {
    if (at->table == Table::Coil) {
      bus->writeCoil(wire, value);
    } else if (at->bit < 0) {
      const std::uint16_t word = value ? 1 : 0;
      bus->writeRegisters(wire, 1, &word);
    } else {
      // A bit inside a register the PLC may share: read, modify, write. The PLC should not
      // write the other bits of a status register while the daemon runs.
      std::uint16_t word = 0;
      bus->readRegisters(wire, 1, &word);
      const auto mask = static_cast<std::uint16_t>(1u << at->bit);
      word = value ? static_cast<std::uint16_t>(word | mask)
                   : static_cast<std::uint16_t>(word & ~mask);
      bus->writeRegisters(wire, 1, &word);
    }
  });
}

void PlcLink::State::writeNumber(const char* name, const std::optional<Location>& at, int value) {
  if (!at) return;
  const auto word = static_cast<std::uint16_t>(value);
  request(name, "writing " + addressText(*at) + " for",
          [&] { bus->writeRegisters(map.wireAddress(at->address), 1, &word); });
}

// Writes registers in as few requests as possible: consecutive addresses go in one request.
void PlcLink::State::writeRegisterRuns(std::vector<RegisterWrite> writes) {
  std::sort(writes.begin(), writes.end(),
            [](const RegisterWrite& a, const RegisterWrite& b) { return a.wire < b.wire; });
  std::size_t begin = 0;
  while (begin < writes.size()) {
    std::size_t end = begin + 1;
    while (end < writes.size() && writes[end].wire == writes[end - 1].wire + 1 &&
           static_cast<int>(end - begin) < kMaxRegistersPerWrite)
      ++end;
    std::vector<std::uint16_t> words;
    std::string names;
    for (std::size_t i = begin; i < end; ++i) {
      words.push_back(writes[i].value);
      if (names.find(writes[i].name) == std::string::npos)
        names += (names.empty() ? "" : ", ") + writes[i].name;
    }
    const int first = writes[begin].wire + map.addressBase;
    const std::string range = end - begin == 1
                                  ? "holding register " + std::to_string(first)
                                  : "holding registers " + std::to_string(first) + ".." +
                                        std::to_string(first + int(end - begin) - 1);
    request(names, "writing " + range + " for", [&] {
      bus->writeRegisters(writes[begin].wire, static_cast<int>(words.size()), words.data());
    });
    begin = end;
  }
}

// ---------------------------------------------------------------------------------------------
// The I/O thread

bool PlcLink::State::sleepFor(std::chrono::milliseconds duration) {
  std::unique_lock lock(mutex);
  wake.wait_for(lock, duration, [&] { return stopping || wakeRequested; });
  wakeRequested = false;
  return !stopping;
}

void PlcLink::State::connect() {
  try {
    bus->connect();
  } catch (const LinkLost& e) {
    backoff = backoff.count() == 0 ? settings.reconnectInitial
                                   : std::min(settings.reconnectMax, backoff * 2);
    std::size_t waiting = 0;
    {
      std::lock_guard lock(mutex);
      waiting = queue.size();
    }
    ++failedConnects;
    // Attempts 1, 2, 4, 8, ...: the retries stay frequent (a PLC that comes back is found
    // within reconnectMax), the log does not fill up with the same line twice a second.
    if ((failedConnects & (failedConnects - 1)) == 0) {
      spdlog::warn(
          "PLC: {}; retrying in {} ms, attempt {} ({} results waiting; next logged at "
          "attempt {})",
          e.what(), backoff.count(), failedConnects, waiting, 2 * failedConnects);
    }
    std::unique_lock lock(mutex);
    wake.wait_for(lock, backoff, [&] { return stopping; });
    return;
  }
  backoff = std::chrono::milliseconds{0};
  if (failedConnects > 0)
    spdlog::info("PLC: reachable again after {} failed attempts", failedConnects);
  failedConnects = 0;
  connected = true;
  {
    std::lock_guard lock(mutex);
    ++stats.connects;
    stats.connected = true;
  }
  spdlog::info("PLC: connected to {}", bus->describe());
}

// After every (re)connect the PLC's view is rebuilt from the daemon's state: the PLC may have
// restarted with cleared registers, or may still hold values from before the loss.
void PlcLink::State::onConnected() {
  headWritten = false;  // the head result is written again, with the same counter
  writeFlag("status.result_valid", map.status.resultValid, false);
  writeFlag("status.busy", map.status.busy, busy);
  writeFlag("status.missed_trigger", map.status.missedTrigger, missedLatched);
  writeFlag("status.completed_toggle", map.status.completedToggle, toggle);
  {
    std::lock_guard lock(mutex);
    daemonStatusDirty = true;
  }
  writeDaemonStatus();
  nextHeartbeat = Clock::now();
}

void PlcLink::State::writeDaemonStatus() {
  bool isReady = false;
  int recipe = -1;
  {
    std::lock_guard lock(mutex);
    if (!daemonStatusDirty) return;
    daemonStatusDirty = false;
    isReady = ready;
    recipe = activeRecipe;
  }
  writeFlag("status.ready", map.status.ready, isReady);
  if (recipe >= 0) writeNumber("status.active_recipe", map.status.activeRecipe, recipe);
}

void PlcLink::State::beat() {
  if (settings.heartbeatPeriod.count() <= 0 || !map.status.heartbeat) return;
  const auto now = Clock::now();
  if (now < nextHeartbeat) return;
  nextHeartbeat = now + settings.heartbeatPeriod;
  writeNumber("status.heartbeat", map.status.heartbeat, ++heartbeat);
}

void PlcLink::State::pollTrigger(bool level) {
  const bool rising = level && !lastTrigger;
  lastTrigger = level;
  if (!rising) return;
  const auto seen = Clock::now();
  if (map.control.enable && !readFlag("control.enable", *map.control.enable)) return;
  if (busy) {
    missedLatched = true;
    writeFlag("status.missed_trigger", map.status.missedTrigger, true);
    std::lock_guard lock(mutex);
    ++stats.missedTriggers;
    spdlog::warn("PLC: trigger while busy (missed trigger {})", stats.missedTriggers);
    return;
  }
  int recipe = -1;
  if (map.control.recipeSelect)
    recipe = readNumber("control.recipe_select", *map.control.recipeSelect);
  busy = true;
  writeFlag("status.busy", map.status.busy, true);
  if (missedLatched) {
    missedLatched = false;
    writeFlag("status.missed_trigger", map.status.missedTrigger, false);
  }
  openTrigger = TriggerTimes{seen, Clock::now()};
  std::lock_guard lock(mutex);
  ++stats.triggers;
  if (recipe >= 0) requestedRecipe = recipe;
  if (triggers.size() >= kTriggerQueueCapacity) {
    spdlog::error("PLC: trigger {} dropped, the daemon has not taken the last {} triggers",
                  triggerSequence + 1, triggers.size());
    triggers.pop_front();
  }
  triggers.push_back({++triggerSequence, recipe, seen});
  triggerArrived.notify_all();
}

void PlcLink::State::writeResult(const Pending& pending, bool clearBusy) {
  const InspectionResult& r = pending.result;
  std::vector<RegisterWrite> writes;
  for (const auto& output : map.results) {
    const auto found = r.values.find(output.name);
    double value = std::numeric_limits<double>::quiet_NaN();
    // Outputs of another recipe: their registers keep what that recipe last wrote.
    if (found == r.values.end() && r.onlyGivenValues) continue;
    if (found == r.values.end())
      spdlog::error("PLC: part '{}' has no value for mapped result '{}'", r.partId, output.name);
    else
      value = found->second;
    const EncodedValue encoded = encodeValue(output, value);
    // NaN is "not measured" (its step failed): written as NaN / 0 without complaint.
    if (encoded.clamped && found != r.values.end() && !std::isnan(value))
      spdlog::error("PLC: part '{}': {} = {} does not fit {} at register {}; written saturated",
                    r.partId, output.name, value, toString(output.type), output.address);
    const int wire = map.wireAddress(output.address);
    for (int i = 0; i < encoded.count; ++i)
      writes.push_back({wire + i, encoded.words[i], "result." + output.name});
  }
  if (map.status.errorCode)
    writes.push_back({map.wireAddress(map.status.errorCode->address),
                      static_cast<std::uint16_t>(r.errorCode), "status.error_code"});
  writeRegisterRuns(std::move(writes));
  // What the PLC watches goes last, so that it finds everything else in place: in free run the
  // counter (the verdict before it), when triggered result valid (the counter before it).
  const bool freeRun = settings.mode == HandshakeMode::FreeRun;
  if (freeRun) {
    writeFlag("status.pass", map.status.pass, r.pass);
    writeFlag("status.error", map.status.error, r.errorCode != 0);
  }
  writeNumber("status.inspection_counter", map.status.inspectionCounter, pending.counter);
  toggle = !toggle;
  writeResultFlags(r.pass, r.errorCode != 0, clearBusy, /*withVerdict=*/!freeRun);
}

// [pass, error,] completed toggle, result valid (and busy = 0 when this result answers the open
// trigger). When these are coils that, together with the daemon's other status coils as filler,
// form one contiguous block, a single request writes them all at once; otherwise one request
// each, result valid (then busy) last.
void PlcLink::State::writeResultFlags(bool pass, bool error, bool clearBusy, bool withVerdict) {
  struct Flag {
    const char* name;
    const std::optional<Location>* at;
    bool value;
  };
  const auto& s = map.status;
  std::vector<Flag> flags;
  if (withVerdict) {
    flags.push_back({"status.pass", &s.pass, pass});
    flags.push_back({"status.error", &s.error, error});
  }
  flags.push_back({"status.completed_toggle", &s.completedToggle, toggle});
  flags.push_back({"status.result_valid", &s.resultValid, true});
  if (clearBusy) flags.push_back({"status.busy", &s.busy, false});
  bool isReady = true;
  {
    std::lock_guard lock(mutex);
    isReady = ready;
  }
  std::vector<Flag> fillers = {{"status.ready", &s.ready, isReady},
                               {"status.missed_trigger", &s.missedTrigger, missedLatched}};
  if (!clearBusy) fillers.push_back({"status.busy", &s.busy, busy});

  std::map<int, std::pair<bool, std::string>> block;  // wire -> value, name
  bool allCoils = true;
  for (const auto& f : flags) {
    if (!*f.at) continue;
    if ((*f.at)->table != Table::Coil) allCoils = false;
    block.emplace(map.wireAddress((*f.at)->address), std::make_pair(f.value, f.name));
  }
  if (allCoils && block.size() > 1) {
    const int first = block.begin()->first;
    const int last = block.rbegin()->first;
    for (const auto& f : fillers) {
      if (!*f.at || (*f.at)->table != Table::Coil) continue;
      const int wire = map.wireAddress((*f.at)->address);
      if (wire > first && wire < last) block.emplace(wire, std::make_pair(f.value, f.name));
    }
    if (static_cast<int>(block.size()) == last - first + 1) {
      std::vector<std::uint8_t> values;
      std::string names;
      for (const auto& [wire, entry] : block) {
        values.push_back(entry.first ? 1 : 0);
        names += (names.empty() ? "" : ", ") + entry.second;
      }
      request(names,
              "writing coils " + std::to_string(first + map.addressBase) + ".." +
                  std::to_string(last + map.addressBase) + " for",
              [&] { bus->writeCoils(first, static_cast<int>(values.size()), values.data()); });
      return;
    }
  }
  for (const auto& f : flags) writeFlag(f.name, *f.at, f.value);
}

void PlcLink::State::deliverHead() {
  Pending head;
  {
    std::lock_guard lock(mutex);
    if (queue.empty()) return;
    head = queue.front();
  }
  const bool answersTrigger = busy;
  writeResult(head, answersTrigger);
  headValidAt = Clock::now();
  headWritten = true;
  if (answersTrigger) {
    busy = false;
    headTrigger = openTrigger;
    openTrigger.reset();
  }
  std::lock_guard lock(mutex);
  ++stats.written;
  if (settings.mode == HandshakeMode::FreeRun) {
    HandshakeTiming timing;
    timing.inspectionCounter = head.counter;
    timing.publishToResultValid = headValidAt - head.publishedAt;
    timings.push_back(timing);
    if (timings.size() > kTimingHistory) timings.pop_front();
    queue.pop_front();
    headWritten = false;
    queueChanged.notify_all();
  }
}

void PlcLink::State::step() {
  {
    std::lock_guard lock(mutex);
    if (dropClearsBusy) {
      dropClearsBusy = false;
      if (busy) {
        busy = false;
        openTrigger.reset();
        writeFlag("status.busy", map.status.busy, false);
      }
    }
  }
  writeDaemonStatus();
  beat();
  if (settings.mode == HandshakeMode::Triggered) {
    pollTrigger(readFlag("control.trigger", *map.control.trigger));
    const bool ack = readFlag("control.result_ack", *map.control.resultAck);
    const bool ackRising = ack && !lastAck;
    lastAck = ack;
    if (headWritten && ackRising) {
      const auto ackSeen = Clock::now();
      writeFlag("status.result_valid", map.status.resultValid, false);
      const auto cleared = Clock::now();
      headWritten = false;
      std::lock_guard lock(mutex);
      const Pending& head = queue.front();
      HandshakeTiming timing;
      timing.inspectionCounter = head.counter;
      if (headTrigger) timing.triggerToBusy = headTrigger->busyWritten - headTrigger->seen;
      timing.publishToResultValid = headValidAt - head.publishedAt;
      timing.resultValidToAck = ackSeen - headValidAt;
      timing.ackToClear = cleared - ackSeen;
      timings.push_back(timing);
      if (timings.size() > kTimingHistory) timings.pop_front();
      headTrigger.reset();
      queue.pop_front();
      ++stats.acknowledged;
      queueChanged.notify_all();
    }
  } else if (map.control.recipeSelect) {
    const int recipe = readNumber("control.recipe_select", *map.control.recipeSelect);
    std::lock_guard lock(mutex);
    requestedRecipe = recipe;
  }
  // Four-phase handshake: the next result waits until the PLC has dropped its acknowledge, so
  // the PLC sees result valid fall between two results.
  const bool ackReleased = settings.mode == HandshakeMode::FreeRun || !lastAck;
  if (!headWritten && ackReleased) deliverHead();
}

void PlcLink::State::run() {
  while (true) {
    {
      std::lock_guard lock(mutex);
      if (stopping) break;
    }
    const bool fresh = !connected;
    if (fresh) {
      connect();
      if (!connected) continue;
    }
    try {
      if (fresh) onConnected();
      step();
    } catch (const TryAgain&) {
      // device busy: the same step runs again after the poll period
    } catch (const LinkLost& e) {
      bus->close();
      connected = false;
      std::lock_guard lock(mutex);
      stats.connected = false;
      ++stats.connectionLosses;
      queueChanged.notify_all();
      spdlog::warn("PLC: link to {} lost ({}); {} results waiting", bus->describe(), e.what(),
                   queue.size());
      continue;
    }
    bool more = false;
    {
      std::lock_guard lock(mutex);
      more =
          !queue.empty() && !headWritten && (settings.mode == HandshakeMode::FreeRun || !lastAck);
    }
    if (!more && !sleepFor(settings.pollPeriod)) break;
  }
}

// ---------------------------------------------------------------------------------------------
// The daemon's side

PlcLink::PlcLink(RegisterMap map, PlcSettings settings) : state_(std::make_unique<State>()) {
  const auto issues = map.validate();
  if (!issues.empty()) {
    std::string message = "invalid PLC register map:";
    for (const auto& issue : issues) message += "\n  " + describe(issue);
    throw std::invalid_argument(message);
  }
  const std::string missing = missingSignals(map, settings.mode);
  if (!missing.empty())
    throw std::invalid_argument(
        "the PLC register map lacks " + missing + " for the " +
        (settings.mode == HandshakeMode::Triggered ? "triggered" : "free-run") + " handshake");
  if (settings.queueCapacity == 0)
    throw std::invalid_argument("the PLC queue capacity must be at least 1");
  state_->map = std::move(map);
  state_->settings = std::move(settings);
  if (state_->settings.role == LinkRole::Server) {
    RegisterServerOptions options;
    options.host = state_->settings.host;
    options.port = state_->settings.port;
    options.coils = 65536;  // the whole address space: any valid map fits
    options.holdingRegisters = 65536;
    state_->server = std::make_unique<RegisterServer>(options);
    state_->bus = makeServerBus(*state_->server);
  } else {
    state_->bus = makeClientBus(state_->settings);
  }
}

PlcLink::~PlcLink() {
  stop();
}

void PlcLink::start() {
  if (state_->thread.joinable()) return;
  {
    std::lock_guard lock(state_->mutex);
    state_->stopping = false;
  }
  state_->thread = std::thread([s = state_.get()] { s->run(); });
}

void PlcLink::stop() {
  {
    std::lock_guard lock(state_->mutex);
    state_->stopping = true;
  }
  state_->wake.notify_all();
  state_->queueChanged.notify_all();
  if (state_->thread.joinable()) state_->thread.join();
  state_->bus->close();
  state_->connected = false;
  std::lock_guard lock(state_->mutex);
  state_->stats.connected = false;
  for (const auto& pending : state_->queue)
    spdlog::error("PLC: result of part '{}' (inspection counter {}) not delivered: link stopped",
                  pending.result.partId, pending.counter);
  state_->stats.abandoned += state_->queue.size();
  state_->queue.clear();
  state_->headWritten = false;
}

bool PlcLink::flush(std::chrono::milliseconds timeout) {
  State& s = *state_;
  std::unique_lock lock(s.mutex);
  s.queueChanged.wait_for(lock, timeout,
                          [&] { return s.queue.empty() || !s.stats.connected || s.stopping; });
  return s.queue.empty();
}

bool PlcLink::publish(InspectionResult result) {
  State& s = *state_;
  std::lock_guard lock(s.mutex);
  ++s.stats.published;
  const std::uint16_t counter = s.nextCounter++;
  if (s.queue.size() >= s.settings.queueCapacity) {
    ++s.stats.dropped;
    s.dropClearsBusy = true;
    spdlog::error(
        "PLC: queue full ({} results waiting): result of part '{}' (inspection counter {}) "
        "dropped; {} dropped so far",
        s.queue.size(), result.partId, counter, s.stats.dropped);
    s.wakeRequested = true;
    s.wake.notify_all();
    return false;
  }
  s.queue.push_back({std::move(result), counter, Clock::now()});
  s.wakeRequested = true;
  s.wake.notify_all();
  return true;
}

std::optional<TriggerEvent> PlcLink::waitTrigger(std::chrono::milliseconds timeout) {
  State& s = *state_;
  std::unique_lock lock(s.mutex);
  s.triggerArrived.wait_for(lock, timeout, [&] { return !s.triggers.empty() || s.stopping; });
  if (s.triggers.empty()) return std::nullopt;
  TriggerEvent event = s.triggers.front();
  s.triggers.pop_front();
  return event;
}

void PlcLink::setReady(bool ready) {
  std::lock_guard lock(state_->mutex);
  state_->daemonStatusDirty = state_->daemonStatusDirty || state_->ready != ready;
  state_->ready = ready;
}

void PlcLink::setActiveRecipe(int recipe) {
  std::lock_guard lock(state_->mutex);
  state_->daemonStatusDirty = state_->daemonStatusDirty || state_->activeRecipe != recipe;
  state_->activeRecipe = recipe;
}

int PlcLink::requestedRecipe() const {
  std::lock_guard lock(state_->mutex);
  return state_->requestedRecipe;
}

PlcLinkStats PlcLink::stats() const {
  std::lock_guard lock(state_->mutex);
  PlcLinkStats stats = state_->stats;
  stats.queueDepth = state_->queue.size();
  return stats;
}

std::vector<HandshakeTiming> PlcLink::takeTimings() {
  std::lock_guard lock(state_->mutex);
  std::vector<HandshakeTiming> out(state_->timings.begin(), state_->timings.end());
  state_->timings.clear();
  return out;
}

const RegisterMap& PlcLink::registerMap() const {
  return state_->map;
}
const PlcSettings& PlcLink::settings() const {
  return state_->settings;
}

int PlcLink::serverPort() const {
  return state_->server ? state_->server->port() : -1;
}

}  // namespace facet::plc
