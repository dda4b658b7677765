// facet plc-sim: a PLC simulator on localhost for demos and manual checks. It serves the station's
// register map over Modbus TCP, raises triggers at a rate, acknowledges results and prints one
// line per result it receives.
#include <atomic>
#include <csignal>
#include <iostream>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "plc/plc_simulator.hpp"
#include "plc/register_map_yaml.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

std::atomic<bool> interrupted{false};
void onSignal(int) {
  interrupted = true;
}

// The map under a dotted key ("plc.register_map") of a YAML file, or the whole file.
plc::RegisterMap loadMap(const std::string& path, const std::string& key) {
  try {
    if (key.empty()) return plc::loadRegisterMap(path);
    YAML::Node node = YAML::LoadFile(path);
    std::string rest = key;
    while (!rest.empty()) {
      const auto dot = rest.find('.');
      const std::string part = rest.substr(0, dot);
      rest = dot == std::string::npos ? "" : rest.substr(dot + 1);
      if (!node.IsMap() || !node[part]) throw InputError(path + ": no key '" + key + "'");
      node = node[part];
    }
    return plc::parseRegisterMap(node, path);
  } catch (const plc::RegisterMapError& e) {
    throw InputError(e.what());
  } catch (const YAML::BadFile&) {
    throw InputError(path + ": cannot read the register map file");
  } catch (const YAML::ParserException& e) {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                     std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

}  // namespace

void addPlcSimCommand(CLI::App& app) {
  struct Options {
    std::string map;
    std::string key;
    std::string host = "127.0.0.1";
    int port = 1502;
    double rate = 0.0;
    bool freeRun = false;
    int ackDelayMs = 0;
    double duration = 0.0;
  };
  auto options = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "plc-sim",
      "Simulate the line's PLC: serve a register map over Modbus TCP, raise triggers, "
      "acknowledge and print results");
  cmd->add_option("--map", options->map, "YAML file holding the register map")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--key", options->key,
                  "dotted key of the map inside the file (e.g. plc.register_map); default: the "
                  "whole file");
  cmd->add_option("--host", options->host, "address to listen on")->capture_default_str();
  cmd->add_option("--port", options->port, "TCP port (0: pick a free one)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--rate", options->rate, "triggers per second (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_flag("--free-run", options->freeRun,
                "no triggers or acknowledges: report each new inspection counter");
  cmd->add_option("--ack-delay", options->ackDelayMs, "milliseconds before acknowledging a result")
      ->capture_default_str()
      ->check(CLI::Range(0, 60000));
  cmd->add_option("--duration", options->duration, "seconds to run (0: until Ctrl-C)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e7));
  cmd->callback([options] {
    plc::RegisterMap map = loadMap(options->map, options->key);
    plc::PlcSimulatorOptions simOptions;
    simOptions.host = options->host;
    simOptions.port = options->port;
    simOptions.triggerRate = options->rate;
    simOptions.mode =
        options->freeRun ? plc::HandshakeMode::FreeRun : plc::HandshakeMode::Triggered;
    simOptions.ackDelay = std::chrono::milliseconds(options->ackDelayMs);
    if (!options->freeRun && (!map.control.trigger || !map.status.resultValid))
      throw InputError(options->map +
                       ": the triggered handshake needs control.trigger and status.result_valid "
                       "(or use --free-run)");
    std::unique_ptr<plc::PlcSimulator> sim;
    try {
      sim = std::make_unique<plc::PlcSimulator>(std::move(map), simOptions);
    } catch (const std::exception& e) {
      throw InputError(e.what());
    }
    sim->onResult([](const plc::ReceivedResult& r) { std::cout << plc::describe(r) << std::endl; });
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::cerr << "plc-sim: serving on " << options->host << ":" << sim->port();
    if (options->rate > 0) std::cerr << ", " << options->rate << " triggers/s";
    std::cerr << std::endl;
    sim->start();
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         std::chrono::duration<double>(options->duration));
    while (!interrupted && (options->duration <= 0 || std::chrono::steady_clock::now() < end))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    sim->stop();
    const auto stats = sim->stats();
    std::cerr << "plc-sim: " << stats.triggersRaised << " triggers, " << stats.results
              << " results, " << stats.missedTriggersSeen << " missed triggers" << std::endl;
  });
}

}  // namespace facet::cli
