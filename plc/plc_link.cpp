#include "plc/plc_link.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <stdexcept>

#include "plc/plc_link_state.hpp"
#include "plc/register_encoding.hpp"

namespace facet::plc {
namespace {

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
