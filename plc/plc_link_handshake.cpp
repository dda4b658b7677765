// The PLC link's I/O thread: connects and reconnects, polls the trigger and the acknowledge,
// writes results, status and heartbeat (the handshake plc_link.hpp describes).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "plc/plc_link_state.hpp"
#include "plc/register_encoding.hpp"

namespace facet::plc {

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

}  // namespace facet::plc
