#pragma once
// PlcSettings: how the daemon reaches the line's PLC and how the handshake behaves. Parsed from
// the station config by config/ (see also register_map_yaml.hpp for the register map itself).

#include <chrono>
#include <cstddef>
#include <string>

namespace facet::plc {

// Who is the Modbus server.
enum class LinkRole {
  Client,  // the daemon connects to the PLC, which serves the registers (the usual wiring)
  Server,  // the daemon serves the registers and the PLC polls it
};

enum class HandshakeMode {
  Triggered,  // PLC raises trigger, daemon answers with busy / result valid, PLC acknowledges
  FreeRun,    // no trigger and no acknowledge: every result is written with the next inspection
              // counter and the completed toggle flipped; the PLC watches the counter
};

enum class Transport {
  Tcp,  // Modbus TCP
  Rtu,  // Modbus RTU over a serial port (client role only)
};

struct PlcSettings {
  LinkRole role = LinkRole::Client;
  HandshakeMode mode = HandshakeMode::Triggered;
  Transport transport = Transport::Tcp;

  // Modbus TCP. Client: the PLC's address. Server: the address the daemon listens on.
  std::string host = "127.0.0.1";
  int port = 502;  // 1..65535; server role may use 0 to pick a free port
  int unitId = 1;  // Modbus unit (slave) id, 0..247; many TCP PLCs ignore it, some need 255

  // Modbus RTU (transport Rtu only).
  std::string serialDevice = "/dev/ttyUSB0";
  int baudRate = 19200;
  char parity = 'E';  // 'N', 'E' or 'O'
  int dataBits = 8;
  int stopBits = 1;

  // Time to wait for the PLC's answer to one request before the link counts as lost.
  std::chrono::milliseconds responseTimeout{500};
  // Period at which the daemon reads the control signals (trigger, acknowledge, recipe, enable).
  // An edge is seen only if the level holds for a poll: the PLC should keep the trigger low (and
  // high) for at least a few periods.
  std::chrono::milliseconds pollPeriod{2};
  // Period of the heartbeat counter; 0 disables the heartbeat.
  std::chrono::milliseconds heartbeatPeriod{1000};

  // Reconnect after a lost link: first wait reconnectInitial, then double up to reconnectMax.
  // The cap bounds how late the daemon notices a PLC that came back (a restarted PLC is back on
  // the line within reconnectMax); a refused connect on a plant network costs next to nothing.
  std::chrono::milliseconds reconnectInitial{100};
  std::chrono::milliseconds reconnectMax{500};

  // Results waiting for the PLC (written but not yet acknowledged, or produced while the link is
  // down). When full, a new result is dropped, counted and logged as an error naming its part.
  std::size_t queueCapacity = 64;
};

}  // namespace facet::plc
