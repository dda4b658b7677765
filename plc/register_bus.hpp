#pragma once
// RegisterBus: the four Modbus operations the handshake needs, on wire addresses, whether the
// daemon is the Modbus client (requests to the PLC) or the server (its own tables). PlcLink's
// handshake is written once against it.

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "plc/plc_settings.hpp"

namespace facet::plc {

class RegisterServer;

// The connection is gone (timeout, reset, refused); the link reconnects.
struct LinkLost : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The peer answered with a Modbus exception (illegal address, device busy, ...).
struct ModbusException : std::runtime_error {
  ModbusException(int code, const std::string& message) : std::runtime_error(message), code(code) {}
  int code;  // libmodbus errno (EMBXILADD, EMBXSBUSY, ...)
  bool deviceBusy() const;
};

class RegisterBus {
 public:
  virtual ~RegisterBus() = default;
  // Opens the connection; throws LinkLost when the peer cannot be reached.
  virtual void connect() = 0;
  virtual void close() = 0;
  virtual std::string describe() const = 0;  // "127.0.0.1:502 unit 1"

  virtual void readCoils(int wire, int count, std::uint8_t* out) = 0;
  virtual void readRegisters(int wire, int count, std::uint16_t* out) = 0;
  virtual void writeCoil(int wire, bool value) = 0;
  virtual void writeCoils(int wire, int count, const std::uint8_t* values) = 0;  // one request
  virtual void writeRegisters(int wire, int count, const std::uint16_t* values) = 0;
};

// The daemon as Modbus client (TCP or RTU, per settings).
std::unique_ptr<RegisterBus> makeClientBus(const PlcSettings& settings);
// The daemon as Modbus server: local access to `server`'s tables (never lost).
std::unique_ptr<RegisterBus> makeServerBus(RegisterServer& server);

}  // namespace facet::plc
